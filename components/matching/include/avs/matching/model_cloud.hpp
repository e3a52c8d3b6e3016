// Model point cloud (M-PCD) from a triangle mesh: uniform area-weighted surface sampling, then
// voxel down-sampling to a target count (paper section 6.3 and 7.2: 302 ken, 488 cube, 248
// cylinder).
#pragma once

#include <cstddef>
#include <cstdint>

#include "avs/geometry/mesh.hpp"
#include "avs/matching/cloud.hpp"

namespace avs::matching {

struct ModelCloudConfig {
  std::size_t target_points = 302;         ///< wanted M-PCD size
  std::size_t surface_samples = 30000;     ///< dense samples drawn before down-sampling
  std::uint32_t seed = 1;                  ///< surface sampling is seeded: same mesh, same cloud
  int max_search_steps = 60;               ///< bisection steps on the voxel size
  std::size_t verification_points = 4000;  ///< dense samples kept to verify initial alignments
};

struct SurfaceSamples {
  Points points_m;
  Points normals;  ///< outward (triangle winding counter-clockwise seen from outside)
};

struct ModelCloud {
  Points points_m;           ///< M-PCD in the model frame
  Points normals;            ///< unit outward normals (mean mesh normal per voxel; may be zero)
  float voxel_size_m = 0;    ///< voxel side that produced the count
  float mean_spacing_m = 0;  ///< mean distance to the nearest other point
  /// Dense uniform surface samples (and outward normals): the initial alignment verifies its
  /// hypotheses against these, fine enough to tell the ken's big cup from its small cup.
  Points dense_points_m;
  Points dense_normals;
};

/// Samples `count` points uniformly over the mesh surface (probability proportional to area).
/// Throws std::invalid_argument if the mesh has no triangle of positive area.
[[nodiscard]] SurfaceSamples sample_surface(const geometry::Mesh& mesh, std::size_t count,
                                            std::uint32_t seed);

/// The largest model, corner to corner, make_model_cloud() accepts: 1000 km, far above any
/// object a depth camera matches (matching warns from 5 m), well below where float coordinates
/// at the voxel sizes it searches stop working.
inline constexpr double kMaxModelSizeM = 1e6;

/// Samples the surface, then searches the voxel size whose down-sampled cloud is closest to
/// config.target_points. Throws std::invalid_argument for a non-finite vertex or a mesh above
/// kMaxModelSizeM across.
[[nodiscard]] ModelCloud make_model_cloud(const geometry::Mesh& mesh,
                                          const ModelCloudConfig& config);

}  // namespace avs::matching
