#include "avs/matching/kd_tree.hpp"

#include <limits>
#include <stdexcept>

#include <nanoflann.hpp>

namespace avs::matching {
namespace {

struct PointsAdaptor {
  const Points* points = nullptr;
  [[nodiscard]] std::size_t kdtree_get_point_count() const { return points->size(); }
  [[nodiscard]] float kdtree_get_pt(std::size_t index, std::size_t dim) const {
    return (*points)[index][static_cast<Eigen::Index>(dim)];
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};

// Result set for the single closest point (Eq. 21).
class NearestResult {
 public:
  [[nodiscard]] bool full() const { return true; }
  bool addPoint(float squared_distance, std::uint32_t index) {
    if (squared_distance < squared_distance_) {
      squared_distance_ = squared_distance;
      index_ = index;
    }
    return true;
  }
  [[nodiscard]] float worstDist() const { return squared_distance_; }
  [[nodiscard]] std::uint32_t index() const { return index_; }

 private:
  float squared_distance_ = std::numeric_limits<float>::max();
  std::uint32_t index_ = 0;
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointsAdaptor>,
                                                 PointsAdaptor, 3, std::uint32_t>;

}  // namespace

struct KdTree::Index {
  PointsAdaptor adaptor;
  Tree tree;
  explicit Index(const Points* points)
      : adaptor{points}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(8)) {}
};

KdTree::KdTree() = default;
KdTree::KdTree(Points points) {
  build(std::move(points));
}
KdTree::~KdTree() = default;
KdTree::KdTree(KdTree&& other) noexcept
    : points_(std::move(other.points_)), index_(std::move(other.index_)) {
  if (index_) index_->adaptor.points = &points_;
}
KdTree& KdTree::operator=(KdTree&& other) noexcept {
  points_ = std::move(other.points_);
  index_ = std::move(other.index_);
  if (index_) index_->adaptor.points = &points_;
  return *this;
}

void KdTree::build(Points points) {
  points_ = std::move(points);
  index_.reset();
  if (!points_.empty()) index_ = std::make_unique<Index>(&points_);
}

std::pair<std::uint32_t, float> KdTree::nearest(const Eigen::Vector3f& query) const {
  if (!index_ || points_.empty()) throw std::logic_error("KdTree::nearest on an empty tree");
  NearestResult result;
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return {result.index(), result.worstDist()};
}

std::size_t KdTree::knn(const Eigen::Vector3f& query, std::size_t k, std::uint32_t* indices,
                        float* squared_distances) const {
  if (!index_ || points_.empty() || k == 0) return 0;
  nanoflann::KNNResultSet<float, std::uint32_t, std::size_t> result(k);
  result.init(indices, squared_distances);
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  return result.size();
}

std::size_t KdTree::radius_search(const Eigen::Vector3f& query, float radius_m,
                                  std::vector<std::pair<std::uint32_t, float>>& out) const {
  out.clear();
  if (!index_ || points_.empty()) return 0;
  nanoflann::SearchParams params;
  params.sorted = false;
  return index_->tree.radiusSearch(query.data(), radius_m * radius_m, out, params);
}

}  // namespace avs::matching
