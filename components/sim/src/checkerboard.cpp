#include "avs/sim/checkerboard.hpp"

#include <cmath>

#include "avs/geometry/primitives.hpp"

namespace avs::sim {

double Checkerboard::albedo(double x_m, double y_m) const {
  const double u = x_m / square_m + 0.5 * squares_x, v = y_m / square_m + 0.5 * squares_y;
  if (!(u >= 0 && u < squares_x && v >= 0 && v < squares_y)) return light_albedo;  // border
  const auto a = static_cast<int>(std::floor(u)), b = static_cast<int>(std::floor(v));
  return (a + b) % 2 == 0 ? dark_albedo : light_albedo;
}

std::string Checkerboard::problem() const {
  if (squares_x < 3 || squares_y < 3) return "a checkerboard needs at least 3 x 3 squares";
  if (squares_x == squares_y) {
    return "squares_x and squares_y must differ (a square board has no unique orientation)";
  }
  if (!(square_m > 0) || !(margin_m >= 0)) return "square_m must be > 0 and margin_m >= 0";
  if (!(dark_albedo >= 0 && dark_albedo < light_albedo && light_albedo <= 1)) {
    return "albedos must satisfy 0 <= dark_albedo < light_albedo <= 1";
  }
  return {};
}

geometry::Mesh make_checkerboard_mesh(const Checkerboard& board) {
  return geometry::make_plane(board.width_m(), board.height_m(), 1);
}

}  // namespace avs::sim
