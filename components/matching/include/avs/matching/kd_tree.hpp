// Nearest-neighbour search over a fixed point set (nanoflann kd-tree, built once).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

/// kd-tree over a point set it copies; queries do not allocate (except radius_search, which
/// appends to a caller-owned vector that can be reused).
class KdTree {
 public:
  KdTree();
  explicit KdTree(Points points);
  ~KdTree();
  KdTree(KdTree&&) noexcept;
  KdTree& operator=(KdTree&&) noexcept;
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  /// Rebuilds the tree over new points.
  void build(Points points);

  [[nodiscard]] const Points& points() const { return points_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }

  /// Closest point (Eq. 21): its index and squared distance. The tree must not be empty.
  [[nodiscard]] std::pair<std::uint32_t, float> nearest(const Eigen::Vector3f& query) const;

  /// k nearest points, closest first; returns how many were found (<= k).
  std::size_t knn(const Eigen::Vector3f& query, std::size_t k, std::uint32_t* indices,
                  float* squared_distances) const;

  /// All points within radius_m; replaces the contents of `out` (index, squared distance).
  std::size_t radius_search(const Eigen::Vector3f& query, float radius_m,
                            std::vector<std::pair<std::uint32_t, float>>& out) const;

 private:
  struct Index;
  Points points_;
  std::unique_ptr<Index> index_;
};

}  // namespace avs::matching
