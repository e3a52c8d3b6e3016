// Camera, projector and stereo calibration (OpenCV), checks and refusals; see solve.hpp.
#include "avs/calib/solve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace avs::calib {
namespace {

/// Fraction of the cells of a 4 x 4 grid over a width x height image reached by `points`.
double grid_coverage(const std::vector<Eigen::Vector2d>& points, int width, int height) {
  constexpr int kCells = 4;
  bool reached[kCells][kCells] = {};
  for (const Eigen::Vector2d& p : points) {
    const int i = std::clamp(static_cast<int>((p.x() + 0.5) * kCells / width), 0, kCells - 1);
    const int j = std::clamp(static_cast<int>((p.y() + 0.5) * kCells / height), 0, kCells - 1);
    reached[j][i] = true;
  }
  int count = 0;
  for (const auto& row : reached) count += static_cast<int>(std::count(row, row + kCells, true));
  return double(count) / (kCells * kCells);
}

geometry::CameraModel lens_from(const cv::Mat& K, const cv::Mat& D, int width, int height) {
  geometry::CameraModel lens;
  lens.width = width;
  lens.height = height;
  lens.fx_px = K.at<double>(0, 0);
  lens.fy_px = K.at<double>(1, 1);
  lens.cx_px = K.at<double>(0, 2);
  lens.cy_px = K.at<double>(1, 2);
  std::vector<double> d(D.begin<double>(), D.end<double>());
  d.resize(d.size() >= 8 ? 8 : 5, 0.0);
  lens.set_distortion_coefficients(d);
  return lens;
}

std::string format(const char* fmt, double a, double b) {
  char text[256];
  std::snprintf(text, sizeof text, fmt, a, b);
  return text;
}

}  // namespace

CalibrationResult solve_calibration(const CaptureInfo& info,
                                    const std::vector<ViewObservation>& views,
                                    const SolveConfig& config) {
  CalibrationResult result;
  // 1. Usable views and their corners (those with projector coordinates, in both images).
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> camera_points, projector_points;
  std::vector<Eigen::Vector2d> all_camera, all_projector;
  long found_corners = 0, undecoded_corners = 0;
  std::vector<std::size_t> used_index;
  std::vector<std::vector<const CornerObservation*>> used_corners;  ///< per used view
  for (std::size_t v = 0; v < views.size(); ++v) {
    const ViewObservation& view = views[v];
    ViewReport report;
    report.name = view.name;
    if (view.board_found) {
      found_corners += static_cast<long>(view.corners.size());
      undecoded_corners += static_cast<long>(view.corners.size()) - view.corners_with_projector();
    }
    const double decoded =
        view.corners.empty() ? 0.0
                             : double(view.corners_with_projector()) / double(view.corners.size());
    if (!view.board_found) {
      report.why_not = view.problem.empty() ? "board not found" : view.problem;
    } else if (view.board_area_fraction < config.min_board_area_fraction) {
      report.why_not = format("board too small in the image (%.2f %% of it, need %.2f %%)",
                              100 * view.board_area_fraction, 100 * config.min_board_area_fraction);
    } else if (decoded < config.min_view_corner_fraction) {
      report.why_not = format("only %.0f %% of the corners decoded (need %.0f %%)", 100 * decoded,
                              100 * config.min_view_corner_fraction);
    } else {
      report.used = true;
      std::vector<cv::Point3f> object;
      std::vector<cv::Point2f> camera, projector;
      std::vector<const CornerObservation*> observed;
      const int nx = info.board.inner_corners_x();
      for (const CornerObservation& c : view.corners) {
        if (!c.has_projector) continue;
        observed.push_back(&c);
        const Eigen::Vector3d p = info.board.corner_board_m(c.index % nx, c.index / nx);
        object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f);
        camera.emplace_back(static_cast<float>(c.camera_px.x()),
                            static_cast<float>(c.camera_px.y()));
        projector.emplace_back(static_cast<float>(c.projector_px.x()),
                               static_cast<float>(c.projector_px.y()));
        all_camera.push_back(c.camera_px);
        all_projector.push_back(c.projector_px);
      }
      report.corners = static_cast<int>(object.size());
      object_points.push_back(std::move(object));
      camera_points.push_back(std::move(camera));
      projector_points.push_back(std::move(projector));
      used_index.push_back(v);
      used_corners.push_back(std::move(observed));
    }
    result.views.push_back(report);
  }
  result.views_used = static_cast<int>(used_index.size());
  const int cw = info.camera_width, ch = info.camera_height;
  const int pw = info.codes.projector_width, ph = info.codes.projector_height;
  result.camera_coverage = grid_coverage(all_camera, cw, ch);
  result.projector_coverage = grid_coverage(all_projector, pw, ph);
  result.undecoded_fraction = found_corners > 0 ? double(undecoded_corners) / found_corners : 1.0;

  // 2. Refusals that need no solve.
  if (result.views_used < config.min_views) {
    result.refusals.push_back("too few usable views: " + std::to_string(result.views_used) +
                              " (need " + std::to_string(config.min_views) +
                              "; see the per-view reasons)");
  }
  if (result.camera_coverage < config.min_coverage) {
    result.refusals.push_back(format(
        "poor coverage of the camera image: corners reach %.0f %% of a 4x4 grid (need %.0f %%)",
        100 * result.camera_coverage, 100 * config.min_coverage));
  }
  if (result.projector_coverage < config.min_coverage) {
    result.refusals.push_back(format(
        "poor coverage of the projector image: corners reach %.0f %% of a 4x4 grid (need %.0f %%)",
        100 * result.projector_coverage, 100 * config.min_coverage));
  }
  if (result.undecoded_fraction > config.max_undecoded_fraction) {
    result.refusals.push_back(format(
        "unstable codes: %.0f %% of the corners have no projector coordinates (at most %.0f %%): "
        "check projector focus, exposure and gamma",
        100 * result.undecoded_fraction, 100 * config.max_undecoded_fraction));
  }
  if (result.views_used < 3) return result;  // OpenCV needs a few views to solve at all

  // 3. Camera, projector, then both jointly (stereoCalibrate refines all intrinsics too).
  const int flags = config.estimate_k3 ? 0 : cv::CALIB_FIX_K3;
  const int projector_flags = config.estimate_projector_k2 ? flags : cv::CALIB_FIX_K2 | flags;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);
  cv::Mat Kc, Dc, Kp, Dp, R, T, E, F, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::calibrateCamera(object_points, camera_points, cv::Size(cw, ch), Kc, Dc, rvecs, tvecs, flags,
                      criteria);
  cv::calibrateCamera(object_points, projector_points, cv::Size(pw, ph), Kp, Dp, rvecs, tvecs,
                      projector_flags, criteria);
  result.stereo_rms_px =
      cv::stereoCalibrate(object_points, camera_points, projector_points, Kc, Dc, Kp, Dp,
                          cv::Size(cw, ch), R, T, E, F, per_view,
                          // CALIB_FIX_K2 holds both lenses' k2 at their single-lens values (the
                          // camera's estimated, the projector's 0).
                          projector_flags | cv::CALIB_USE_INTRINSIC_GUESS, criteria);

  // 4. The model: p_projector = R p_camera + T (stereoCalibrate's convention and ours).
  decode::SensorGeometry& g = result.geometry;
  g.camera = lens_from(Kc, Dc, cw, ch);
  g.projector = lens_from(Kp, Dp, pw, ph);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) g.R_projector_camera(i, j) = R.at<double>(i, j);
    g.t_projector_camera_m[i] = T.at<double>(i);
  }
  g.layout = info.depth_code_layout;

  // 5. Per-view and overall reprojection errors (OpenCV's, with its jointly fitted poses).
  double camera_sum2 = 0, projector_sum2 = 0;
  long points = 0;
  for (std::size_t u = 0; u < used_index.size(); ++u) {
    ViewReport& report = result.views[used_index[u]];
    report.camera_rms_px = per_view.at<double>(static_cast<int>(u), 0);
    report.projector_rms_px = per_view.at<double>(static_cast<int>(u), 1);
    camera_sum2 += report.camera_rms_px * report.camera_rms_px * report.corners;
    projector_sum2 += report.projector_rms_px * report.projector_rms_px * report.corners;
    points += report.corners;
  }
  // 5b. Per corner, through the final model (CornerError): the board pose from the view's
  // camera corners, the projector through the solved R, T.
  for (std::size_t u = 0; u < used_index.size(); ++u) {
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(object_points[u], camera_points[u], Kc, Dc, rvec, tvec)) continue;
    cv::Mat R_board;
    cv::Rodrigues(rvec, R_board);
    cv::Mat R_projector_board = R * R_board, rvec_projector;
    cv::Rodrigues(R_projector_board, rvec_projector);
    const cv::Mat tvec_projector = R * tvec + T;
    std::vector<cv::Point2f> at_camera, at_projector;
    cv::projectPoints(object_points[u], rvec, tvec, Kc, Dc, at_camera);
    cv::projectPoints(object_points[u], rvec_projector, tvec_projector, Kp, Dp, at_projector);
    for (std::size_t k = 0; k < object_points[u].size(); ++k) {
      const CornerObservation& c = *used_corners[u][k];
      CornerError e;
      e.view = views[used_index[u]].name;
      e.index = c.index;
      e.camera_px = c.camera_px;
      e.projector_px = c.projector_px;
      e.camera_residual_px = c.camera_px - Eigen::Vector2d(at_camera[k].x, at_camera[k].y);
      e.projector_residual_px =
          c.projector_px - Eigen::Vector2d(at_projector[k].x, at_projector[k].y);
      e.window_fraction = c.window_fraction;
      e.homography_rms_px = c.homography_rms_px;
      result.corners.push_back(e);
    }
  }
  result.camera_rms_px = std::sqrt(camera_sum2 / static_cast<double>(points));
  result.projector_rms_px = std::sqrt(projector_sum2 / static_cast<double>(points));
  if (!(result.camera_rms_px <= config.max_camera_rms_px)) {
    result.refusals.push_back(format("camera reprojection RMS %.3f px above %.3f px",
                                     result.camera_rms_px, config.max_camera_rms_px));
  }
  if (!(result.projector_rms_px <= config.max_projector_rms_px)) {
    result.refusals.push_back(format("projector reprojection RMS %.3f px above %.3f px",
                                     result.projector_rms_px, config.max_projector_rms_px));
  }
  for (const geometry::CameraModel* lens : {&g.camera, &g.projector}) {
    if (const std::string why = lens->problem(); !why.empty()) {
      result.refusals.push_back("solved lens is not usable: " + why);
    }
  }
  result.accepted = result.refusals.empty();
  return result;
}

decode::GrayImage8 coverage_image(const CaptureInfo& info,
                                  const std::vector<ViewObservation>& views,
                                  const CalibrationResult& result, bool projector) {
  decode::GrayImage8 image;
  image.width = projector ? info.codes.projector_width : info.camera_width;
  image.height = projector ? info.codes.projector_height : info.camera_height;
  image.pixels.assign(static_cast<std::size_t>(image.width) * image.height, 0);
  const auto set = [&image](int x, int y, std::uint8_t value) {
    if (x >= 0 && y >= 0 && x < image.width && y < image.height) {
      image.pixels[static_cast<std::size_t>(y) * image.width + x] = value;
    }
  };
  for (int k = 1; k < 4; ++k) {  // the coverage grid
    for (int x = 0; x < image.width; ++x) set(x, k * image.height / 4, 80);
    for (int y = 0; y < image.height; ++y) set(k * image.width / 4, y, 80);
  }
  for (std::size_t v = 0; v < views.size() && v < result.views.size(); ++v) {
    if (!result.views[v].used) continue;
    for (const CornerObservation& c : views[v].corners) {
      if (!c.has_projector) continue;
      const Eigen::Vector2d p = projector ? c.projector_px : c.camera_px;
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) set(x + dx, y + dy, 255);
      }
    }
  }
  return image;
}

std::string corner_errors_csv(const CalibrationResult& r) {
  std::ostringstream out;
  out << "view,corner,camera_x_px,camera_y_px,camera_dx_px,camera_dy_px,projector_x_px,"
         "projector_y_px,projector_dx_px,projector_dy_px,window_fraction,homography_rms_px\n";
  char line[512];
  for (const CornerError& e : r.corners) {
    std::snprintf(line, sizeof line, "%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.4f\n",
                  e.view.c_str(), e.index, e.camera_px.x(), e.camera_px.y(),
                  e.camera_residual_px.x(), e.camera_residual_px.y(), e.projector_px.x(),
                  e.projector_px.y(), e.projector_residual_px.x(), e.projector_residual_px.y(),
                  e.window_fraction, e.homography_rms_px);
    out << line;
  }
  return out.str();
}

std::string summary_text(const CalibrationResult& r) {
  std::ostringstream out;
  char line[512];
  out << (r.accepted ? "calibration accepted\n" : "calibration REFUSED\n");
  for (const std::string& why : r.refusals) out << "  refused: " << why << "\n";
  std::snprintf(line, sizeof line,
                "views used %d of %zu; reprojection RMS camera %.3f px, projector %.3f px "
                "(stereo %.3f px); coverage camera %.0f %%, projector %.0f %%; corners without "
                "codes %.1f %%\n",
                r.views_used, r.views.size(), r.camera_rms_px, r.projector_rms_px, r.stereo_rms_px,
                100 * r.camera_coverage, 100 * r.projector_coverage, 100 * r.undecoded_fraction);
  out << line;
  for (const ViewReport& v : r.views) {
    if (v.used) {
      std::snprintf(line, sizeof line,
                    "  %-12s %3d corners, RMS camera %.3f px, projector %.3f px\n", v.name.c_str(),
                    v.corners, v.camera_rms_px, v.projector_rms_px);
    } else {
      std::snprintf(line, sizeof line, "  %-12s not used: %s\n", v.name.c_str(), v.why_not.c_str());
    }
    out << line;
  }
  const decode::SensorGeometry& g = r.geometry;
  std::snprintf(line, sizeof line,
                "camera    f %.2f / %.2f px, c %.2f / %.2f px\nprojector f %.2f / %.2f px, c "
                "%.2f / %.2f px\nprojector centre in the camera frame %.4f %.4f %.4f m\n",
                g.camera.fx_px, g.camera.fy_px, g.camera.cx_px, g.camera.cy_px, g.projector.fx_px,
                g.projector.fy_px, g.projector.cx_px, g.projector.cy_px,
                g.projector_centre_camera_m().x(), g.projector_centre_camera_m().y(),
                g.projector_centre_camera_m().z());
  out << line;
  return out.str();
}

}  // namespace avs::calib
