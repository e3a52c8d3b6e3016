// Voxel down-sampling: one point per occupied cube of side voxel_size_m, at the centroid of the
// points inside it (paper section 6.3, used for both the S-PCD and the M-PCD).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

/// Reusable buffers so repeated down-sampling does not allocate once warmed up.
struct VoxelGridScratch {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
};

/// Writes the centroid of every occupied voxel to `out` (cleared first), in ascending voxel-key
/// order (deterministic). When `normals_in` is given, `normals_out` receives the normalised mean
/// normal of each voxel (zero if the normals cancel).
void voxel_downsample(const Points& in, float voxel_size_m, Points& out, VoxelGridScratch& scratch,
                      const Points* normals_in = nullptr, Points* normals_out = nullptr);

/// Convenience overload that allocates.
[[nodiscard]] Points voxel_downsample(const Points& in, float voxel_size_m);

}  // namespace avs::matching
