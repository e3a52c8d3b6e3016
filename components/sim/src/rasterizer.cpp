// Scanline rasteriser with edge functions: per row, the span inside all three edges is
// solved for directly, so the inner loop is a plain depth compare-and-store.
#include "avs/sim/rasterizer.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Geometry>

namespace avs::sim {
namespace {

struct ScreenVertex {
  float u, v, w;  ///< pixel coordinates and 1/z
};

ScreenVertex project(const PinholeView& view, const Eigen::Vector3f& p) {
  const float w = 1.0f / p.z();
  return {view.fx_px * p.x() * w + view.cx_px, view.fy_px * p.y() * w + view.cy_px, w};
}

/// Edge p->q as E(x, y) = a x + b y + c, positive inside a counter-clockwise (u right, v down
/// positive area) triangle; `slack` widens it by about 1e-3 px so neighbours overlap.
struct Edge {
  float a, b, c, slack;
  Edge(const ScreenVertex& p, const ScreenVertex& q) {
    a = -(q.v - p.v);
    b = q.u - p.u;
    c = -(a * p.u + b * p.v);
    slack = 1e-3f * std::sqrt(a * a + b * b);
  }
};

void raster_screen_triangle(const PinholeView& view, ScreenVertex p0, ScreenVertex p1,
                            ScreenVertex p2, std::int32_t id, DepthBuffer& buffer) {
  float area = (p1.u - p0.u) * (p2.v - p0.v) - (p1.v - p0.v) * (p2.u - p0.u);
  if (area < 0) {
    std::swap(p1, p2);
    area = -area;
  }
  if (!(area > 1e-9f)) return;  // degenerate or NaN
  const int row_end = view.last_row > 0 ? view.last_row : view.height;
  const int col_end = view.last_col > 0 ? view.last_col : view.width;
  const int y_begin =
      std::max(view.first_row, static_cast<int>(std::ceil(std::min({p0.v, p1.v, p2.v}))));
  const int y_end =
      std::min(row_end - 1, static_cast<int>(std::floor(std::max({p0.v, p1.v, p2.v}))));
  const float u_min = std::min({p0.u, p1.u, p2.u}), u_max = std::max({p0.u, p1.u, p2.u});
  if (y_begin > y_end || u_max < static_cast<float>(view.first_col) - 0.5f ||
      u_min > static_cast<float>(col_end) - 0.5f)
    return;

  const std::array<Edge, 3> edges = {Edge(p1, p2), Edge(p2, p0), Edge(p0, p1)};
  // w(x, y) = sum_i lambda_i w_i with lambda_i = E_i / area: a plane in (x, y).
  const float inv_area = 1.0f / area;
  const float dw_dx = (edges[0].a * p0.w + edges[1].a * p1.w + edges[2].a * p2.w) * inv_area;
  const float dw_dy = (edges[0].b * p0.w + edges[1].b * p1.w + edges[2].b * p2.w) * inv_area;
  const float w_00 = (edges[0].c * p0.w + edges[1].c * p1.w + edges[2].c * p2.w) * inv_area;
  const float x_lo = std::max(static_cast<float>(view.first_col), std::ceil(u_min));
  const float x_hi = std::min(static_cast<float>(col_end - 1), std::floor(u_max));

  for (int y = y_begin; y <= y_end; ++y) {
    float left = x_lo, right = x_hi;
    bool empty = false;
    for (const Edge& e : edges) {  // a x + (b y + c) >= -slack
      const float rest = e.b * static_cast<float>(y) + e.c + e.slack;
      if (e.a > 0) {
        left = std::max(left, -rest / e.a);
      } else if (e.a < 0) {
        right = std::min(right, -rest / e.a);
      } else if (rest < 0) {
        empty = true;
      }
    }
    if (empty || left > right) continue;
    const int x0 = static_cast<int>(std::ceil(left)), x1 = static_cast<int>(std::floor(right));
    float* depth = buffer.inv_depth.data() + static_cast<std::ptrdiff_t>(y) * buffer.width;
    std::int32_t* ids = buffer.triangle.data() + static_cast<std::ptrdiff_t>(y) * buffer.width;
    const float w_row = w_00 + dw_dy * static_cast<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const float w = w_row + dw_dx * static_cast<float>(x);
      if (w > depth[x]) {
        depth[x] = w;
        ids[x] = id;
      }
    }
  }
}

/// Clips the triangle against z >= near (Sutherland-Hodgman, one plane): 0, 3 or 4 corners.
int clip_near(const std::array<Eigen::Vector3f, 3>& in, float near_m,
              std::array<Eigen::Vector3f, 4>& out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3f& a = in[i];
    const Eigen::Vector3f& b = in[(i + 1) % 3];
    const bool a_in = a.z() >= near_m, b_in = b.z() >= near_m;
    if (a_in) out[n++] = a;
    if (a_in != b_in) {
      const float s = (near_m - a.z()) / (b.z() - a.z());
      out[n++] = a + s * (b - a);
    }
  }
  return n;
}

}  // namespace

void PixelBox::add(const PixelBox& b) {
  if (b.empty()) return;
  if (empty()) {
    *this = b;
    return;
  }
  x0 = std::min(x0, b.x0);
  y0 = std::min(y0, b.y0);
  x1 = std::max(x1, b.x1);
  y1 = std::max(y1, b.y1);
}

void DepthBuffer::reset(int w, int h) {
  width = w;
  height = h;
  inv_depth.assign(static_cast<std::size_t>(w) * h, 0.0f);
  triangle.assign(static_cast<std::size_t>(w) * h, -1);
}

void rasterize(const PinholeView& view, const std::vector<Eigen::Vector3f>& vertices_view,
               const std::vector<Eigen::Vector3i>& triangles, std::int32_t id_offset,
               bool cull_back_faces, DepthBuffer& buffer) {
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const std::array<Eigen::Vector3f, 3> p = {vertices_view[triangles[t][0]],
                                              vertices_view[triangles[t][1]],
                                              vertices_view[triangles[t][2]]};
    if (p[0].z() < view.near_m && p[1].z() < view.near_m && p[2].z() < view.near_m) continue;
    if (cull_back_faces && (p[1] - p[0]).cross(p[2] - p[0]).dot(p[0]) >= 0) continue;
    const auto id = static_cast<std::int32_t>(id_offset + static_cast<std::int32_t>(t));
    if (p[0].z() >= view.near_m && p[1].z() >= view.near_m && p[2].z() >= view.near_m) {
      raster_screen_triangle(view, project(view, p[0]), project(view, p[1]), project(view, p[2]),
                             id, buffer);
      continue;
    }
    std::array<Eigen::Vector3f, 4> clipped;
    const int n = clip_near(p, view.near_m, clipped);
    for (int k = 1; k + 1 < n; ++k) {
      raster_screen_triangle(view, project(view, clipped[0]), project(view, clipped[k]),
                             project(view, clipped[k + 1]), id, buffer);
    }
  }
}

}  // namespace avs::sim
