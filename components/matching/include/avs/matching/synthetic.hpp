// Synthetic objects and depth images for tests and benchmarks: built-in meshes (10 cm cube,
// cylinder, an asymmetric ken-like shape) and a z-buffer depth renderer of a posed mesh, so
// scenes have a known ground-truth pose. Not a camera simulator (no projector, no code errors).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "avs/geometry/mesh.hpp"
#include "avs/matching/cloud.hpp"
#include "avs/matching/pose_error.hpp"

namespace avs::matching {

/// Closed cube of side side_m centred on the origin.
[[nodiscard]] geometry::Mesh make_cube_mesh(float side_m = 0.1F);
/// Closed cylinder, axis z, centred on the origin.
[[nodiscard]] geometry::Mesh make_cylinder_mesh(float radius_m = 0.035F, float height_m = 0.12F,
                                                int segments = 48);
/// Ken-like shape (kendama stick): handle along z with a spike on top, crosspiece along x with
/// a big cup (+x end, rim radius 24 mm) and a smaller cup (-x end, rim radius 19 mm). Its only
/// near-symmetry is the end-for-end flip (rotation by pi about z) that swaps the cups.
[[nodiscard]] geometry::Mesh make_ken_like_mesh(int segments = 32);

/// A built-in test object with the paper's M-PCD size and i_number (section 7.2).
struct ObjectPreset {
  std::string name;
  geometry::Mesh mesh;
  std::size_t model_points = 0;  ///< paper: 302 ken, 488 cube, 248 cylinder
  std::size_t scene_points = 0;  ///< i_number, paper: 250 ken, 350 cube, 300 cylinder
  Symmetry symmetry = Symmetry::none;
};

/// ken (ken-like mesh), cube (10 cm), cylinder (radius 35 mm, height 120 mm).
[[nodiscard]] std::vector<ObjectPreset> builtin_objects();

/// Random orientation, origin within a few centimetres of the optical axis at distance_m.
[[nodiscard]] Eigen::Isometry3f random_object_pose(std::uint32_t seed, float distance_m = 0.6F);

/// Depth image owned by value.
struct DepthImage {
  std::vector<float> depth_m;  ///< 0 where no surface
  int width_px = 0;
  int height_px = 0;
  [[nodiscard]] DepthView view() const { return {depth_m.data(), width_px, height_px, width_px}; }
  [[nodiscard]] std::size_t valid_pixels() const;
};

/// Renders the mesh seen by the camera (z-buffer over pixel centres; both triangle sides).
/// Pinhole only: throws std::invalid_argument for a camera with lens distortion.
[[nodiscard]] DepthImage render_depth(const geometry::Mesh& mesh,
                                      const Eigen::Isometry3f& T_camera_model,
                                      const geometry::CameraModel& camera);

/// Adds seeded Gaussian noise of sigma_m to every valid depth.
void add_depth_noise(DepthImage& image, float sigma_m, std::uint32_t seed);

/// Uniformly random rotation (seeded generator state passed in).
[[nodiscard]] Eigen::Matrix3f random_rotation(std::uint32_t seed);

}  // namespace avs::matching
