// Board corners (OpenCV) and projector coordinates by local homographies (Moreno-Taubin).
#include "avs/calib/observe.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace avs::calib {
namespace {

cv::Mat as_mat(const decode::GrayImage8& image) {
  // OpenCV only reads it.
  return cv::Mat(image.height, image.width, CV_8UC1,
                 const_cast<std::uint8_t*>(image.pixels.data()));
}

/// Decoded projector coordinate per camera pixel along one axis; NaN where not decoded.
struct AxisDecode {
  std::vector<float> position;
};

/// Gray code of `bits` positive/negative pairs starting at frame `first` -> DMD position
/// (pixel centre of the code). Bits by the sign of positive - negative (Eq. 2 with psi = 0);
/// a pixel is decoded when lit (mask) and every judged bit is stable.
AxisDecode decode_axis(const BoardView& view, std::size_t first, const decode::CodeLayout& layout,
                       const std::vector<std::uint8_t>& lit, const ObserveConfig& config) {
  const std::size_t n = lit.size();
  std::vector<std::uint32_t> gray(n, 0);
  std::vector<std::uint8_t> stable(n, 1);
  for (int k = 0; k < layout.bit_count; ++k) {
    const std::uint8_t* pos = view.frames[first + 2 * k].pixels.data();
    const std::uint8_t* neg = view.frames[first + 2 * k + 1].pixels.data();
    for (std::size_t i = 0; i < n; ++i) {
      const int d = int(pos[i]) - int(neg[i]);
      gray[i] = (gray[i] << 1) | (d > 0 ? 1u : 0u);
      if (std::abs(d) < config.stable_bit_dn) stable[i] = 0;
    }
  }
  AxisDecode out;
  out.position.assign(n, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    if (!lit[i] || !stable[i]) continue;
    const auto code = static_cast<int>(decode::gray_to_binary(gray[i]));
    if (code >= layout.code_count) continue;
    out.position[i] = static_cast<float>(layout.first_row + layout.rows_per_code * code +
                                         0.5 * (layout.rows_per_code - 1));
  }
  return out;
}

/// Moreno-Taubin: the homography from the camera pixels of the window to their decoded
/// projector coordinates, robustly fitted (RANSAC, then refined on its inliers), maps the
/// corner to the projector.
void locate_in_projector(CornerObservation& corner, const AxisDecode& columns,
                         const AxisDecode& rows, int width, int height, double code_width_px,
                         const ObserveConfig& config) {
  const int h = config.window_half_px;
  const int cx = static_cast<int>(std::lround(corner.camera_px.x()));
  const int cy = static_cast<int>(std::lround(corner.camera_px.y()));
  std::vector<cv::Point2f> camera, projector;
  int window = 0;
  for (int y = cy - h; y <= cy + h; ++y) {
    for (int x = cx - h; x <= cx + h; ++x) {
      ++window;
      if (x < 0 || y < 0 || x >= width || y >= height) continue;
      const std::size_t i = static_cast<std::size_t>(y) * width + x;
      if (std::isnan(columns.position[i]) || std::isnan(rows.position[i])) continue;
      camera.emplace_back(static_cast<float>(x), static_cast<float>(y));
      projector.emplace_back(columns.position[i], rows.position[i]);
    }
  }
  corner.window_fraction = double(camera.size()) / window;
  if (corner.window_fraction < config.min_window_fraction || camera.size() < 8) return;
  std::vector<std::uint8_t> inlier_mask;
  // RANSAC's threshold: a code and a half (the quantisation spans one code).
  const cv::Mat H =
      cv::findHomography(camera, projector, cv::RANSAC, 1.5 * code_width_px, inlier_mask);
  if (H.empty()) return;
  double sum2 = 0;
  int inliers = 0;
  std::vector<cv::Point2f> mapped;
  cv::perspectiveTransform(camera, mapped, H);
  for (std::size_t k = 0; k < camera.size(); ++k) {
    if (!inlier_mask[k]) continue;
    const cv::Point2f d = mapped[k] - projector[k];
    sum2 += d.dot(d);
    ++inliers;
  }
  corner.homography_inliers = inliers;
  corner.homography_rms_px = inliers > 0 ? std::sqrt(sum2 / inliers) : 0.0;
  if (inliers < 8 || corner.homography_rms_px > config.max_homography_rms_codes * code_width_px) {
    return;
  }
  std::vector<cv::Point2f> at_corner;
  cv::perspectiveTransform(
      std::vector<cv::Point2f>{cv::Point2f(static_cast<float>(corner.camera_px.x()),
                                           static_cast<float>(corner.camera_px.y()))},
      at_corner, H);
  corner.projector_px = {at_corner[0].x, at_corner[0].y};
  corner.has_projector = true;
}

}  // namespace

int ViewObservation::corners_with_projector() const {
  return static_cast<int>(std::count_if(
      corners.begin(), corners.end(), [](const CornerObservation& c) { return c.has_projector; }));
}

std::vector<Eigen::Vector2d> find_board_corners(const decode::GrayImage8& white,
                                                const sim::Checkerboard& board,
                                                int max_subpixel_half_window_px) {
  std::vector<cv::Point2f> found;
  const cv::Size pattern(board.inner_corners_x(), board.inner_corners_y());
  if (!cv::findChessboardCornersSB(as_mat(white), pattern, found,
                                   cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) {
    return {};
  }
  // Refined by cornerSubPix: findChessboardCornersSB's corners alone were biased through the
  // camera's lens distortion (simulator, 16 views: focal 0.28 % and rotation 0.13 deg off; with
  // the refinement 0.08 % and 0.04 deg). The window stays inside the squares: at most 0.4 of
  // the smallest corner spacing, at most max_subpixel_half_window_px.
  double spacing = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < found.size(); ++k) {
    const bool row_end = (k + 1) % static_cast<std::size_t>(pattern.width) == 0;
    if (!row_end) spacing = std::min(spacing, cv::norm(found[k + 1] - found[k]));
    if (k + static_cast<std::size_t>(pattern.width) < found.size()) {
      spacing = std::min(spacing, cv::norm(found[k + pattern.width] - found[k]));
    }
  }
  const int half = std::min(max_subpixel_half_window_px, static_cast<int>(0.4 * spacing));
  if (half >= 2) {
    cv::cornerSubPix(as_mat(white), found, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  }
  std::vector<Eigen::Vector2d> corners;
  for (const cv::Point2f& p : found) corners.emplace_back(p.x, p.y);
  return corners;
}

ViewObservation observe_view(const BoardView& view, const CaptureInfo& info,
                             const ObserveConfig& config) {
  ViewObservation out;
  out.name = view.name;
  const std::vector<FrameId> frames = capture_frames(info.codes);
  if (view.frames.size() != frames.size()) {
    throw std::invalid_argument("calib: view '" + view.name + "' has " +
                                std::to_string(view.frames.size()) + " frames, expected " +
                                std::to_string(frames.size()));
  }
  const int width = info.camera_width, height = info.camera_height;
  for (const decode::GrayImage8& f : view.frames) {
    if (f.width != width || f.height != height) {
      throw std::invalid_argument("calib: view '" + view.name + "': a frame is " +
                                  std::to_string(f.width) + "x" + std::to_string(f.height) +
                                  ", the camera " + std::to_string(width) + "x" +
                                  std::to_string(height));
    }
  }
  // 1. Corners in the white frame.
  const std::vector<Eigen::Vector2d> corners =
      find_board_corners(view.frames[0], info.board, config.max_subpixel_half_window_px);
  if (corners.empty()) {
    out.problem = "board not found in the white frame";
    return out;
  }
  out.board_found = true;
  std::vector<cv::Point2f> hull_input, hull;
  for (const Eigen::Vector2d& c : corners) {
    hull_input.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
  }
  cv::convexHull(hull_input, hull);
  out.board_area_fraction = cv::contourArea(hull) / (double(width) * height);
  // 2. Column and row codes (frames 2.. and 2 + 2 * column bits ..).
  const std::size_t n = static_cast<std::size_t>(width) * height;
  std::vector<std::uint8_t> lit(n);
  for (std::size_t i = 0; i < n; ++i) {
    lit[i] =
        int(view.frames[0].pixels[i]) - int(view.frames[1].pixels[i]) >= config.min_contrast_dn;
  }
  const AxisDecode columns = decode_axis(view, 2, info.codes.columns, lit, config);
  const AxisDecode rows =
      decode_axis(view, 2 + 2 * static_cast<std::size_t>(info.codes.columns.bit_count),
                  info.codes.rows, lit, config);
  // 3. Projector coordinates per corner.
  for (std::size_t k = 0; k < corners.size(); ++k) {
    CornerObservation corner;
    corner.index = static_cast<int>(k);
    corner.camera_px = corners[k];
    locate_in_projector(corner, columns, rows, width, height,
                        std::max(info.codes.columns.rows_per_code, info.codes.rows.rows_per_code),
                        config);
    out.corners.push_back(corner);
  }
  return out;
}

}  // namespace avs::calib
