// Exact k-nearest-neighbour search over a small cloud rebuilt every frame (the S-PCD outlier
// test, Sec. 6.1), without heap allocation once its buffers have grown to the largest cloud:
// a uniform grid of cells over the cloud's bounding box, points counting-sorted by cell, and
// a search in growing shells of cells. (The kd-tree it replaces, nanoflann 1.4, frees and
// mallocs its node pool on every build: the matcher's last allocations per frame, issue 16.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

class NeighbourGrid {
 public:
  /// Indexes `points`, which must stay alive and unchanged while knn() is used. Cells hold
  /// about one point each in a cloud that fills its bounding box (fewer on a surface), at most
  /// 64 along an axis.
  void rebuild(const Points& points);

  /// The k nearest points to `query` (any point, not necessarily of the cloud), closest first,
  /// as a kd-tree gives them; returns how many were found (<= k). `indices` and
  /// `squared_distances` hold at least k entries.
  std::size_t knn(const Eigen::Vector3f& query, std::size_t k, std::uint32_t* indices,
                  float* squared_distances) const;

 private:
  const Points* points_ = nullptr;
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  float cell_m_ = 1.0F;
  int cells_[3] = {1, 1, 1};
  std::vector<std::uint32_t>
      cell_start_;                      ///< per cell, first index into order_; one more at the end
  std::vector<std::uint32_t> order_;    ///< point indices sorted by cell
  std::vector<std::uint32_t> cell_of_;  ///< per point, its cell
};

}  // namespace avs::matching
