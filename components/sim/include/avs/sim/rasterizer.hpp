// Triangle rasterisation into an inverse-depth buffer with triangle ids: the geometry pass
// of the renderer, run once per pose for the camera and once for the projector.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace avs::sim {

/// Pinhole projection used while rasterising (no distortion: the renderer's lenses are
/// ideal pinholes). Pixel centres at integer coordinates.
struct PinholeView {
  int width = 0;
  int height = 0;
  float fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
  float near_m = 0.05f;  ///< triangles are clipped against z = near_m
  int first_row = 0;     ///< rows outside [first_row, last_row) are not rasterised
  int last_row = 0;      ///< 0 = height
  int first_col = 0;     ///< columns outside [first_col, last_col) are not rasterised
  int last_col = 0;      ///< 0 = width
};

/// Inclusive rectangle of pixels; empty when x1 < x0 or y1 < y0.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
  long area() const { return empty() ? 0 : static_cast<long>(x1 - x0 + 1) * (y1 - y0 + 1); }
  /// Grows to the bounding box of both.
  void add(const PixelBox& b);
};

/// Per pixel: 1/z of the nearest surface (0 = nothing) and its triangle id (-1 = nothing).
struct DepthBuffer {
  int width = 0;
  int height = 0;
  std::vector<float> inv_depth;
  std::vector<std::int32_t> triangle;

  void reset(int w, int h);
};

/// Rasterises `triangles` (indices into `vertices_view`, points in the view frame, z
/// forward) with ids id_offset + index. Back faces (clockwise on screen) are skipped when
/// `cull_back_faces`. Triangles crossing the near plane are clipped. Shared edges are covered
/// by both neighbours (a conservative epsilon), so closed meshes show no cracks.
void rasterize(const PinholeView& view, const std::vector<Eigen::Vector3f>& vertices_view,
               const std::vector<Eigen::Vector3i>& triangles, std::int32_t id_offset,
               bool cull_back_faces, DepthBuffer& buffer);

}  // namespace avs::sim
