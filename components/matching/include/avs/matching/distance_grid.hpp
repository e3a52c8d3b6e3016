// Truncated closest-point distance to a fixed point set, tabulated on a regular grid (built once
// per model). The initial alignment scores LRF-pair hypotheses by summed closest-point distances
// (paper section 6.1); a lookup here replaces a kd-tree query (Eq. 21) by a few loads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "avs/matching/cloud.hpp"

namespace avs::matching {

/// d(x) = min(|x - closest point|, truncation) at the cell corners (stored in 8 bits, steps of
/// truncation / 255, so the table stays in cache), trilinearly interpolated or read at the nearest
/// corner; the truncation outside the grid, which covers the points' bounding box plus the
/// truncation.
class DistanceGrid {
 public:
  DistanceGrid() = default;
  /// Throws std::invalid_argument for an empty point set or a non-positive cell or truncation.
  /// The cell grows (cell_m() tells) when the table would have more than max_cells corners
  /// (0: no limit), so a large mesh does not cost its cube in memory and build time.
  DistanceGrid(const Points& points_m, float cell_m, float truncation_m,
               std::size_t max_cells = kDefaultMaxCells);

  static constexpr std::size_t kDefaultMaxCells = std::size_t{4} << 20;  ///< 4 MiB of 8-bit corners

  [[nodiscard]] bool empty() const { return values_.empty(); }
  [[nodiscard]] float truncation_m() const { return truncation_m_; }
  [[nodiscard]] float cell_m() const { return cell_m_; }
  [[nodiscard]] std::size_t cells() const { return values_.size(); }

  /// Interpolated truncated distance at p (same frame as the points).
  [[nodiscard]] float distance(const Eigen::Vector3f& p) const {
    const Eigen::Vector3f g = (p - origin_m_) * inverse_cell_;
    if (!inside(g)) return truncation_m_;
    const int x = static_cast<int>(g.x());
    const int y = static_cast<int>(g.y());
    const int z = static_cast<int>(g.z());
    const float fx = g.x() - static_cast<float>(x);
    const float fy = g.y() - static_cast<float>(y);
    const float fz = g.z() - static_cast<float>(z);
    const std::uint8_t* c = values_.data() + index(x, y, z);
    const std::size_t sy = nx_;
    const std::size_t sz = nx_ * ny_;
    const auto lerp = [](float a, float b, float f) { return a + f * (b - a); };
    const auto at = [c](std::size_t offset) { return static_cast<float>(c[offset]); };
    const float c0 = lerp(lerp(at(0), at(1), fx), lerp(at(sy), at(sy + 1), fx), fy);
    const float c1 = lerp(lerp(at(sz), at(sz + 1), fx), lerp(at(sz + sy), at(sz + sy + 1), fx), fy);
    return lerp(c0, c1, fz) * step_m_;
  }

  /// Truncated distance at the corner nearest to p (one load; error up to half a cell diagonal).
  [[nodiscard]] float nearest_distance(const Eigen::Vector3f& p) const {
    const Eigen::Vector3f g = (p - origin_m_) * inverse_cell_ + Eigen::Vector3f::Constant(0.5F);
    if (!inside(g)) return truncation_m_;
    return static_cast<float>(values_[index(static_cast<int>(g.x()), static_cast<int>(g.y()),
                                            static_cast<int>(g.z()))]) *
           step_m_;
  }

 private:
  [[nodiscard]] bool inside(const Eigen::Vector3f& g) const {
    return g.x() >= 0.0F && g.y() >= 0.0F && g.z() >= 0.0F && g.x() < limit_.x() &&
           g.y() < limit_.y() && g.z() < limit_.z();
  }
  [[nodiscard]] std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * ny_ + static_cast<std::size_t>(y)) * nx_ +
           static_cast<std::size_t>(x);
  }

  std::vector<std::uint8_t> values_;  // at cell corners, x fastest, in steps of step_m_
  Eigen::Vector3f origin_m_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f limit_ = Eigen::Vector3f::Zero();  // interpolation cells per axis
  std::size_t nx_ = 0;
  std::size_t ny_ = 0;
  std::size_t nz_ = 0;
  float cell_m_ = 0.0F;
  float inverse_cell_ = 0.0F;
  float truncation_m_ = 0.0F;
  float step_m_ = 0.0F;  // truncation / 255
};

}  // namespace avs::matching
