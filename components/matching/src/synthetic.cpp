#include "avs/matching/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace avs::matching {
namespace {

// Revolves a profile (r, z) about the local z axis. The solid must lie to the left of the
// profile's direction of travel so triangles wind counter-clockwise seen from outside.
void append_revolution(geometry::Mesh& mesh, const Eigen::Isometry3f& T_model_local,
                       const std::vector<Eigen::Vector2f>& profile, int segments) {
  const int base = static_cast<int>(mesh.vertices.size());
  for (const auto& rz : profile) {
    for (int j = 0; j < segments; ++j) {
      const float theta =
          2.0F * std::numbers::pi_v<float> * static_cast<float>(j) / static_cast<float>(segments);
      mesh.vertices.push_back(T_model_local * Eigen::Vector3f(rz.x() * std::cos(theta),
                                                              rz.x() * std::sin(theta), rz.y()));
    }
  }
  for (int i = 0; i + 1 < static_cast<int>(profile.size()); ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = base + i * segments + j;
      const int b = base + i * segments + (j + 1) % segments;
      const int c = base + (i + 1) * segments + (j + 1) % segments;
      const int d = base + (i + 1) * segments + j;
      mesh.triangles.emplace_back(a, b, c);
      mesh.triangles.emplace_back(a, c, d);
    }
  }
}

Eigen::Isometry3f frame(const Eigen::Matrix3f& rotation, const Eigen::Vector3f& origin) {
  Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
  t.linear() = rotation;
  t.translation() = origin;
  return t;
}

}  // namespace

geometry::Mesh make_cube_mesh(float side_m) {
  geometry::Mesh mesh;
  const float h = 0.5F * side_m;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back((i & 1) != 0 ? h : -h, (i & 2) != 0 ? h : -h, (i & 4) != 0 ? h : -h);
  }
  // Faces as quads (counter-clockwise seen from outside).
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh.triangles.emplace_back(q[0], q[1], q[2]);
    mesh.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return mesh;
}

geometry::Mesh make_cylinder_mesh(float radius_m, float height_m, int segments) {
  geometry::Mesh mesh;
  const float h = 0.5F * height_m;
  append_revolution(mesh, Eigen::Isometry3f::Identity(),
                    {{0.0F, -h}, {radius_m, -h}, {radius_m, h}, {0.0F, h}}, segments);
  return mesh;
}

geometry::Mesh make_ken_like_mesh(int segments) {
  geometry::Mesh mesh;
  const Eigen::Matrix3f z_to_x =
      Eigen::AngleAxisf(std::numbers::pi_v<float> / 2, Eigen::Vector3f::UnitY()).toRotationMatrix();
  const Eigen::Matrix3f z_to_minus_x =
      Eigen::AngleAxisf(-std::numbers::pi_v<float> / 2, Eigen::Vector3f::UnitY())
          .toRotationMatrix();
  // Handle (radius 9.5 mm) and spike along z.
  append_revolution(mesh, Eigen::Isometry3f::Identity(),
                    {{0.0F, -0.075F}, {0.0095F, -0.075F}, {0.0095F, 0.03F}, {0.0F, 0.03F}},
                    segments);
  append_revolution(mesh, Eigen::Isometry3f::Identity(),
                    {{0.0F, 0.045F}, {0.008F, 0.045F}, {0.0015F, 0.085F}, {0.0F, 0.085F}},
                    segments);
  // Crosspiece along x at z = 35 mm.
  append_revolution(mesh, frame(z_to_x, {0.0F, 0.0F, 0.035F}),
                    {{0.0F, -0.034F}, {0.013F, -0.034F}, {0.013F, 0.034F}, {0.0F, 0.034F}},
                    segments);
  // Big cup at +x (rim radius 24 mm, 8 mm deep), small cup at -x (rim 19 mm, 6 mm deep).
  append_revolution(mesh, frame(z_to_x, {0.034F, 0.0F, 0.035F}),
                    {{0.0F, 0.0F},
                     {0.013F, 0.0F},
                     {0.024F, 0.016F},
                     {0.021F, 0.016F},
                     {0.008F, 0.008F},
                     {0.0F, 0.008F}},
                    segments);
  append_revolution(mesh, frame(z_to_minus_x, {-0.034F, 0.0F, 0.035F}),
                    {{0.0F, 0.0F},
                     {0.013F, 0.0F},
                     {0.019F, 0.012F},
                     {0.0165F, 0.012F},
                     {0.007F, 0.006F},
                     {0.0F, 0.006F}},
                    segments);
  return mesh;
}

std::size_t DepthImage::valid_pixels() const {
  return static_cast<std::size_t>(
      std::count_if(depth_m.begin(), depth_m.end(), [](float z) { return z > 0.0F; }));
}

DepthImage render_depth(const geometry::Mesh& mesh, const Eigen::Isometry3f& T_camera_model,
                        const geometry::CameraModel& lens) {
  if (lens.has_distortion()) {
    throw std::invalid_argument("render_depth: pinhole only, the camera has lens distortion");
  }
  struct {
    float fx_px, fy_px, cx_px, cy_px;
    int width_px, height_px;
  } const camera{static_cast<float>(lens.fx_px),
                 static_cast<float>(lens.fy_px),
                 static_cast<float>(lens.cx_px),
                 static_cast<float>(lens.cy_px),
                 lens.width,
                 lens.height};
  DepthImage image;
  image.width_px = camera.width_px;
  image.height_px = camera.height_px;
  image.depth_m.assign(
      static_cast<std::size_t>(camera.width_px) * static_cast<std::size_t>(camera.height_px), 0.0F);
  for (const auto& triangle : mesh.triangles) {
    Eigen::Vector3f p[3];
    Eigen::Vector2f q[3];
    bool in_front = true;
    for (int k = 0; k < 3; ++k) {
      p[k] = T_camera_model * mesh.vertices[static_cast<std::size_t>(triangle[k])];
      if (p[k].z() < 1e-3F) in_front = false;
      q[k] = {camera.fx_px * p[k].x() / p[k].z() + camera.cx_px,
              camera.fy_px * p[k].y() / p[k].z() + camera.cy_px};
    }
    if (!in_front) continue;
    const float area =
        (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
    if (std::abs(area) < 1e-9F) continue;
    const int u0 =
        std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int u1 = std::min(camera.width_px - 1,
                            static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int v0 =
        std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int v1 = std::min(camera.height_px - 1,
                            static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        const Eigen::Vector2f s(static_cast<float>(u), static_cast<float>(v));
        float w[3];
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector2f& a = q[(k + 1) % 3];
          const Eigen::Vector2f& b = q[(k + 2) % 3];
          w[k] = ((b - a).x() * (s - a).y() - (b - a).y() * (s - a).x()) / area;
        }
        if (w[0] < 0.0F || w[1] < 0.0F || w[2] < 0.0F) continue;
        // Perspective-correct depth: 1/z is affine in the image.
        const float z = 1.0F / (w[0] / p[0].z() + w[1] / p[1].z() + w[2] / p[2].z());
        float& pixel =
            image.depth_m[static_cast<std::size_t>(v) * static_cast<std::size_t>(camera.width_px) +
                          static_cast<std::size_t>(u)];
        if (pixel == 0.0F || z < pixel) pixel = z;
      }
    }
  }
  return image;
}

void add_depth_noise(DepthImage& image, float sigma_m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0F, sigma_m);
  for (auto& z : image.depth_m) {
    if (z > 0.0F) z += noise(rng);
  }
}

std::vector<ObjectPreset> builtin_objects() {
  std::vector<ObjectPreset> objects;
  objects.push_back({"ken", make_ken_like_mesh(), 302, 250, Symmetry::none});
  objects.push_back({"cube", make_cube_mesh(0.1F), 488, 350, Symmetry::cube});
  objects.push_back(
      {"cylinder", make_cylinder_mesh(0.035F, 0.12F), 248, 300, Symmetry::cylinder_z});
  return objects;
}

Eigen::Isometry3f random_object_pose(std::uint32_t seed, float distance_m) {
  std::mt19937 rng(seed * 2654435761U + 1U);
  std::uniform_real_distribution<float> offset(-0.03F, 0.03F);
  Eigen::Isometry3f pose = Eigen::Isometry3f::Identity();
  pose.linear() = random_rotation(seed);
  pose.translation() = Eigen::Vector3f(offset(rng), offset(rng), distance_m + offset(rng));
  return pose;
}

Eigen::Matrix3f random_rotation(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.0F, 1.0F);
  Eigen::Quaternionf q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
  q.normalize();
  return q.toRotationMatrix();
}

}  // namespace avs::matching
