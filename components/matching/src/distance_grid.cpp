#include "avs/matching/distance_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "avs/matching/kd_tree.hpp"

namespace avs::matching {

DistanceGrid::DistanceGrid(const Points& points_m, float cell_m, float truncation_m,
                           std::size_t max_cells)
    : cell_m_(cell_m),
      inverse_cell_(1.0F / cell_m),
      truncation_m_(truncation_m),
      step_m_(truncation_m / 255.0F) {
  if (points_m.empty()) throw std::invalid_argument("DistanceGrid: no points");
  if (!(cell_m > 0.0F) || !(truncation_m > 0.0F)) {
    throw std::invalid_argument("DistanceGrid: cell (" + std::to_string(cell_m) +
                                " m) and truncation (" + std::to_string(truncation_m) +
                                " m) must be > 0");
  }
  Eigen::Vector3f low = points_m.front();
  Eigen::Vector3f high = points_m.front();
  for (const auto& p : points_m) {
    if (!p.allFinite()) throw std::invalid_argument("DistanceGrid: a point is not finite");
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  origin_m_ = low.array() - truncation_m;
  const Eigen::Vector3f extent = (high - low).array() + 2.0F * truncation_m;
  // A large object: coarser cells, so the table keeps at most max_cells corners.
  const double volume = static_cast<double>(extent.x()) * extent.y() * extent.z();
  if (max_cells > 0 &&
      volume / std::pow(static_cast<double>(cell_m_), 3.0) > static_cast<double>(max_cells)) {
    cell_m_ = static_cast<float>(std::cbrt(volume / static_cast<double>(max_cells)));
    inverse_cell_ = 1.0F / cell_m_;
  }
  // Corners per axis, counted in double: at 1e12 m over millimetre cells a float or size_t
  // product would overflow.
  const auto corners = [&](float length) {
    return std::ceil(static_cast<double>(length) / static_cast<double>(cell_m_)) + 2.0;
  };
  // The volume rule undercounts a flat or thin object (its thin axes keep their boundary
  // corners whatever the cell): grow the cell until the real count fits. Each step removes
  // about half the corners, so this ends within a few dozen steps (issue 20: a mesh scaled by
  // 1e12 spun here).
  // (Once the cell exceeds the largest extent every axis has 3 corners: the loop stops there.)
  while (max_cells > 0 && cell_m_ < extent.maxCoeff() &&
         corners(extent.x()) * corners(extent.y()) * corners(extent.z()) >
             static_cast<double>(max_cells)) {
    cell_m_ *= 1.26F;
    inverse_cell_ = 1.0F / cell_m_;
  }
  nx_ = static_cast<std::size_t>(corners(extent.x()));
  ny_ = static_cast<std::size_t>(corners(extent.y()));
  nz_ = static_cast<std::size_t>(corners(extent.z()));
  limit_ = Eigen::Vector3f(static_cast<float>(nx_ - 1), static_cast<float>(ny_ - 1),
                           static_cast<float>(nz_ - 1));
  values_.assign(nx_ * ny_ * nz_, 255);
  // Eq. 21 at every corner, through a kd-tree over the points (built once, here).
  const KdTree tree(points_m);
  const float truncation_squared = truncation_m * truncation_m;
  std::size_t at = 0;
  for (std::size_t z = 0; z < nz_; ++z) {
    for (std::size_t y = 0; y < ny_; ++y) {
      for (std::size_t x = 0; x < nx_; ++x, ++at) {
        const Eigen::Vector3f corner =
            origin_m_ + cell_m_ * Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y),
                                                  static_cast<float>(z));
        const float squared = tree.nearest(corner).second;
        const float distance = std::sqrt(std::min(squared, truncation_squared));
        values_[at] = static_cast<std::uint8_t>(std::lround(distance / step_m_));
      }
    }
  }
}

}  // namespace avs::matching
