#include "avs/matching/neighbour_grid.hpp"

#include <algorithm>
#include <cmath>

namespace avs::matching {
namespace {

constexpr int kMaxCellsPerAxis = 64;

/// The cell of a coordinate in cell units, clamped to [0, cells) before the conversion to int
/// (a NaN or a coordinate billions of cells away must not reach it).
int clamp_cell(float coordinate, int cells) {
  if (!(coordinate > 0.0F)) return 0;
  if (coordinate >= static_cast<float>(cells - 1)) return cells - 1;
  return static_cast<int>(coordinate);
}

}  // namespace

void NeighbourGrid::rebuild(const Points& points) {
  const std::size_t n = points.size();
  points_ = n == 0 ? nullptr : &points;  // an empty cloud is never read again
  if (n == 0) {
    cells_[0] = cells_[1] = cells_[2] = 1;
    cell_start_.assign(2, 0);
    order_.clear();
    return;
  }
  Eigen::Vector3f lo = points[0], hi = points[0];
  for (const auto& p : points) {
    if (!p.allFinite()) continue;  // lands in a border cell; its distances are NaN anyway
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!lo.allFinite() || !hi.allFinite()) lo = hi = Eigen::Vector3f::Zero();
  const Eigen::Vector3f extent = (hi - lo).cwiseMax(1e-6F);
  // About one point per cell if the cloud filled its box; never more than 64 cells an axis.
  const float volume = extent.x() * extent.y() * extent.z();
  cell_m_ = std::max(std::cbrt(volume / static_cast<float>(n)),
                     extent.maxCoeff() / static_cast<float>(kMaxCellsPerAxis));
  origin_ = lo;
  std::size_t total = 1;
  for (int a = 0; a < 3; ++a) {
    cells_[a] = clamp_cell(extent[a] / cell_m_, kMaxCellsPerAxis) + 1;  // 1 .. 64
    total *= static_cast<std::size_t>(cells_[a]);
  }
  // Counting sort of the points by cell (buffers keep their capacity from frame to frame).
  cell_start_.assign(total + 1, 0);
  cell_of_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f g = (points[i] - origin_) / cell_m_;
    const auto c = static_cast<std::uint32_t>(
        (clamp_cell(g.z(), cells_[2]) * cells_[1] + clamp_cell(g.y(), cells_[1])) * cells_[0] +
        clamp_cell(g.x(), cells_[0]));
    cell_of_[i] = c;
    ++cell_start_[c + 1];
  }
  for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
  order_.resize(n);
  // Stable within a cell (index order), so results do not depend on anything but the cloud.
  for (std::size_t i = 0; i < n; ++i)
    order_[cell_start_[cell_of_[i]]++] = static_cast<std::uint32_t>(i);
  for (std::size_t c = total; c > 0; --c) cell_start_[c] = cell_start_[c - 1];
  cell_start_[0] = 0;
}

std::size_t NeighbourGrid::knn(const Eigen::Vector3f& query, std::size_t k, std::uint32_t* indices,
                               float* squared_distances) const {
  if (k == 0 || points_ == nullptr || points_->empty()) return 0;
  const Points& points = *points_;
  const Eigen::Vector3f g = (query - origin_) / cell_m_;
  const int home[3] = {clamp_cell(g.x(), cells_[0]), clamp_cell(g.y(), cells_[1]),
                       clamp_cell(g.z(), cells_[2])};
  std::size_t found = 0;
  auto offer = [&](std::uint32_t index) {
    // Summed x, y, z in turn, as nanoflann's L2 metric does (KdTree): the same distances to
    // the last bit, so the outlier test keeps every point it kept before.
    const Eigen::Vector3f& p = points[index];
    const float dx = p.x() - query.x(), dy = p.y() - query.y(), dz = p.z() - query.z();
    float d = dx * dx;
    d += dy * dy;
    d += dz * dz;
    if (found == k && d >= squared_distances[k - 1]) return;
    // Insertion into the sorted best list (ties keep the earlier point first).
    std::size_t at = found < k ? found++ : k - 1;
    while (at > 0 && squared_distances[at - 1] > d) {
      squared_distances[at] = squared_distances[at - 1];
      indices[at] = indices[at - 1];
      --at;
    }
    squared_distances[at] = d;
    indices[at] = index;
  };
  const int max_ring = std::max({cells_[0], cells_[1], cells_[2]});
  for (int ring = 0; ring <= max_ring; ++ring) {
    // Every cell whose Chebyshev distance from the home cell is exactly `ring`.
    const int z0 = std::max(0, home[2] - ring), z1 = std::min(cells_[2] - 1, home[2] + ring);
    const int y0 = std::max(0, home[1] - ring), y1 = std::min(cells_[1] - 1, home[1] + ring);
    const int x0 = std::max(0, home[0] - ring), x1 = std::min(cells_[0] - 1, home[0] + ring);
    auto visit = [&](int x, int y, int z) {
      const std::size_t c = (static_cast<std::size_t>(z) * static_cast<std::size_t>(cells_[1]) +
                             static_cast<std::size_t>(y)) *
                                static_cast<std::size_t>(cells_[0]) +
                            static_cast<std::size_t>(x);
      for (std::uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) offer(order_[i]);
    };
    for (int z = z0; z <= z1; ++z) {
      const bool z_face = std::abs(z - home[2]) == ring;
      for (int y = y0; y <= y1; ++y) {
        if (z_face || std::abs(y - home[1]) == ring) {
          for (int x = x0; x <= x1; ++x) visit(x, y, z);
        } else {  // inside the block in y and z: only the two x faces are on the ring
          if (home[0] - ring >= 0) visit(home[0] - ring, y, z);
          if (ring > 0 && home[0] + ring < cells_[0]) visit(home[0] + ring, y, z);
        }
      }
    }
    // Every point not yet offered lies in a cell more than `ring` cells from the home cell
    // along some axis: at least `ring` whole cells from the query (which is in the home cell,
    // or beyond the box on the side of it where the home cell is the last).
    // A thousandth of a cell less, for the rounding of the cell coordinates.
    if (found == k) {
      const float reach = (static_cast<float>(ring) - 1e-3F) * cell_m_;
      if (reach > 0.0F && squared_distances[k - 1] <= reach * reach) break;
    }
  }
  return found;
}

}  // namespace avs::matching
