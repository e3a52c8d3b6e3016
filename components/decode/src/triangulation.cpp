#include "avs/decode/triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace avs::decode {
namespace {

void check_geometry(const SensorGeometry& g) {
  const CodeLayout& l = g.layout;
  if (g.camera.width <= 0 || g.camera.height <= 0 || g.camera.fx_px <= 0 || g.camera.fy_px <= 0 ||
      g.projector.fx_px <= 0 || g.projector.fy_px <= 0) {
    throw std::invalid_argument("sensor geometry: camera/projector intrinsics not set (camera " +
                                std::to_string(g.camera.width) + "x" +
                                std::to_string(g.camera.height) + ")");
  }
  if (l.bit_count < 1 || l.bit_count > 15 || l.code_count < 1 ||
      l.code_count > (1 << l.bit_count) || l.rows_per_code < 1) {
    throw std::invalid_argument("sensor geometry: invalid code layout (" +
                                std::to_string(l.bit_count) + " bits, " +
                                std::to_string(l.code_count) + " codes, " +
                                std::to_string(l.rows_per_code) + " rows per code)");
  }
}

}  // namespace

DepthTable::DepthTable(const SensorGeometry& g, int subcode_steps) {
  check_geometry(g);
  width_ = g.camera.width;
  height_ = g.camera.height;
  invalid_index_ = 1 << g.layout.bit_count;

  // Per-pixel undistorted camera rays (x, y, 1).
  ray_x_.resize(static_cast<std::size_t>(pixel_count()));
  ray_y_.resize(ray_x_.size());
  for (int v = 0; v < height_; ++v) {
    for (int u = 0; u < width_; ++u) {
      const Eigen::Vector3d r = g.camera.ray(u, v);
      ray_x_[static_cast<std::size_t>(v) * width_ + u] = static_cast<float>(r.x());
      ray_y_[static_cast<std::size_t>(v) * width_ + u] = static_cast<float>(r.y());
    }
  }

  // Separable? (bitwise: the fast kernel then gives exactly the per-pixel result.)
  bool separable = true;
  for (int v = 0; v < height_ && separable; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * width_;
    for (int u = 0; u < width_; ++u) {
      if (ray_x_[row + u] != ray_x_[static_cast<std::size_t>(u)] ||
          ray_y_[row + u] != ray_y_[row]) {
        separable = false;
        break;
      }
    }
  }
  if (separable) {
    column_ray_x_.assign(ray_x_.begin(), ray_x_.begin() + width_);
    row_ray_y_.resize(static_cast<std::size_t>(height_));
    for (int v = 0; v < height_; ++v) {
      row_ray_y_[static_cast<std::size_t>(v)] = ray_y_[static_cast<std::size_t>(v) * width_];
    }
  }

  // Per-code planes through the projector centre and the code's centre row. With projector
  // distortion the row's rays are not exactly coplanar: fit the plane (smallest eigenvector of
  // the rays' scatter matrix, the plane passing through the centre by construction).
  const float nan = std::numeric_limits<float>::quiet_NaN();
  planes_.assign(4 * static_cast<std::size_t>(invalid_index_ + 1), nan);
  const int column_step = g.projector.has_distortion() ? 1 : std::max(1, g.projector.width - 1);
  for (int code = 0; code < g.layout.code_count; ++code) {
    fit_row_plane(g, g.code_centre_row(code), column_step,
                  planes_.data() + 4 * static_cast<std::size_t>(code), &max_plane_fit_error_);
  }
  if (subcode_steps > 0) {
    // Sub-code planes: projector rows from the lower edge of code 0 to the upper edge of the
    // last code in steps of 1 / subcode_steps code. With projector distortion the fit uses
    // every 8th column (the planes are a fit either way; see max_plane_fit_error()).
    subcode_steps_ = subcode_steps;
    const int count = g.layout.code_count * subcode_steps + 1;
    subcode_planes_.assign(4 * static_cast<std::size_t>(count), nan);
    const int sub_step = g.projector.has_distortion() ? 8 : column_step;
    double ignored = 0;
    for (int j = 0; j < count; ++j) {
      const double code = static_cast<double>(j) / subcode_steps - 0.5;
      fit_row_plane(g, subcode_row(g, code), sub_step,
                    subcode_planes_.data() + 4 * static_cast<std::size_t>(j), &ignored);
    }
    if (!g.projector.has_distortion()) {
      // Eq. 4's projector row: plane(v) = P_2 - v P_3 through the projector centre, with
      // v = alpha + beta u. A point z (x, y, 1) on it: z (plane_xyz . r) + plane_w = 0. Scaled
      // to numbers near 1 (the depth does not depend on the plane's scale).
      const Eigen::Matrix<double, 3, 4> P = g.projector_matrix();
      const double alpha = subcode_row(g, 0.0);
      const double beta = subcode_row(g, 1.0) - alpha;
      const Eigen::Vector4d plane0 = P.row(1).transpose() - alpha * P.row(2).transpose();
      const Eigen::Vector4d plane1 = -beta * P.row(2).transpose();
      const double scale = std::max(plane0.cwiseAbs().maxCoeff(), plane1.cwiseAbs().maxCoeff());
      if (scale > 0) {
        const auto f = [scale](double v) { return static_cast<float>(v / scale); };
        linear_subcode_planes_ = {f(plane0.x()), f(plane0.y()),
                                  f(plane0.z()), f(-plane0.w()),
                                  f(plane1.x()), f(plane1.y()),
                                  f(plane1.z()), f(-plane1.w()),
                                  -0.5f,         static_cast<float>(g.layout.code_count) - 0.5f};
        has_linear_subcode_planes_ = true;
      }
    }
  }
}

double DepthTable::subcode_row(const SensorGeometry& g, double code) {
  return g.layout.first_row + g.layout.rows_per_code * code + 0.5 * (g.layout.rows_per_code - 1);
}

void DepthTable::fit_row_plane(const SensorGeometry& g, double row, int column_step, float* abc0,
                               double* max_fit_error) {
  const Eigen::Vector3d centre = g.projector_centre_camera_m();
  const Eigen::Matrix3d R_camera_projector = g.R_projector_camera.transpose();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> rays;
  for (int u = 0; u < g.projector.width; u += column_step) {
    const Eigen::Vector3d d = (R_camera_projector * g.projector.ray(u, row)).normalized();
    scatter += d * d.transpose();
    rays.push_back(d);
  }
  if (rays.size() < 2 || (g.projector.width - 1) % column_step != 0) {
    rays.push_back((R_camera_projector * g.projector.ray(g.projector.width - 1, row)).normalized());
    scatter += rays.back() * rays.back().transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  for (const auto& d : rays) *max_fit_error = std::max(*max_fit_error, std::abs(normal.dot(d)));
  // Plane n . X = n . centre; a camera ray X = z (x, y, 1) meets it at z = 1 / (n' . (x, y, 1))
  // with n' = n / (n . centre).
  const double offset = normal.dot(centre);
  if (std::abs(offset) < 1e-12) return;  // plane through the camera centre: no depth (NaN)
  const Eigen::Vector3d abc = normal / offset;
  for (int i = 0; i < 3; ++i) abc0[i] = static_cast<float>(abc[i]);
  abc0[3] = 0.0f;
}

ReferenceTriangulator::ReferenceTriangulator(const SensorGeometry& g)
    : C_(g.camera_matrix()), P_(g.projector_matrix()), code_count_(g.layout.code_count) {
  check_geometry(g);
  row_of_code_.resize(static_cast<std::size_t>(code_count_));
  for (int code = 0; code < code_count_; ++code) row_of_code_[code] = g.code_centre_row(code);
  undistorted_pixel_.resize(static_cast<std::size_t>(g.camera.width) * g.camera.height);
  for (int v = 0; v < g.camera.height; ++v) {
    for (int u = 0; u < g.camera.width; ++u) {
      const Eigen::Vector3d r = g.camera.ray(u, v);
      undistorted_pixel_[static_cast<std::size_t>(v) * g.camera.width + u] = {
          g.camera.fx_px * r.x() + g.camera.cx_px, g.camera.fy_px * r.y() + g.camera.cy_px};
    }
  }
}

Eigen::Vector3d ReferenceTriangulator::point(int pixel_index, int code) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (code < 0 || code >= code_count_) return {nan, nan, nan};
  const double xc = undistorted_pixel_[pixel_index].x();
  const double yc = undistorted_pixel_[pixel_index].y();
  const double yp = row_of_code_[code];
  // Eq. 4.
  Eigen::Matrix3d F;
  F << C_(0, 0) - C_(2, 0) * xc, C_(0, 1) - C_(2, 1) * xc, C_(0, 2) - C_(2, 2) * xc,
      C_(1, 0) - C_(2, 0) * yc, C_(1, 1) - C_(2, 1) * yc, C_(1, 2) - C_(2, 2) * yc,
      P_(1, 0) - P_(2, 0) * yp, P_(1, 1) - P_(2, 1) * yp, P_(1, 2) - P_(2, 2) * yp;
  const Eigen::Vector3d R(C_(2, 3) * xc - C_(0, 3), C_(2, 3) * yc - C_(1, 3),
                          P_(2, 3) * yp - P_(1, 3));
  const auto lu = F.partialPivLu();
  if (!(std::abs(lu.determinant()) > 1e-12)) return {nan, nan, nan};
  return lu.solve(R);
}

}  // namespace avs::decode
