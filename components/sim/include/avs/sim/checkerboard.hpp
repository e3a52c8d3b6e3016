// A printed checkerboard calibration target (issue 14): the pattern is the albedo of a flat
// plate, which the renderer integrates over each camera pixel (antialiased edges, as a real
// lens and sensor blur them). Plain C++/Eigen.
#pragma once

#include <string>

#include <Eigen/Core>

#include "avs/geometry/mesh.hpp"

namespace avs::sim {

/// Board frame: origin at the plate's centre, x along the squares_x direction, y along
/// squares_y, z the plate's normal (the printed side faces +z).
struct Checkerboard {
  int squares_x = 10;  ///< squares along x (inner corners: squares_x - 1)
  int squares_y = 7;   ///< squares along y
  double square_m = 0.03;
  double margin_m = 0.03;  ///< light border around the squares (one square, for the detector)
  double dark_albedo = 0.12;
  double light_albedo = 0.8;

  int inner_corners_x() const { return squares_x - 1; }
  int inner_corners_y() const { return squares_y - 1; }
  int corner_count() const { return inner_corners_x() * inner_corners_y(); }
  double width_m() const { return squares_x * square_m + 2 * margin_m; }
  double height_m() const { return squares_y * square_m + 2 * margin_m; }
  /// Inner corner (i, j), i < inner_corners_x(), j < inner_corners_y(), in the board frame.
  /// Row-major index j * inner_corners_x() + i is OpenCV's chessboard corner order.
  Eigen::Vector3d corner_board_m(int i, int j) const {
    return {(i + 1 - 0.5 * squares_x) * square_m, (j + 1 - 0.5 * squares_y) * square_m, 0.0};
  }
  /// Albedo at (x, y) of the board frame: square (0, 0) (most negative x and y) is dark.
  double albedo(double x_m, double y_m) const;
  /// Empty when usable; otherwise what is wrong.
  std::string problem() const;
};

/// The plate: width_m() x height_m(), facing +z, two triangles.
geometry::Mesh make_checkerboard_mesh(const Checkerboard& board);

}  // namespace avs::sim
