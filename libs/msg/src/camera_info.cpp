#include "avs/msg/camera_info.hpp"

#include <algorithm>
#include <array>
#include <span>

#include "avs/runtime/sample.hpp"

namespace avs::msg {

void to_camera_info(const geometry::CameraModel& camera, msgs::sensor_msgs::CameraInfo& out) {
  out.width = static_cast<std::uint32_t>(camera.width);
  out.height = static_cast<std::uint32_t>(camera.height);
  runtime::set_string(out.distortion_model, camera.distortion_model());
  std::array<double, 8> d;
  const std::size_t n = camera.distortion_coefficients(d);
  runtime::resize_sequence(out.d, static_cast<std::uint32_t>(n));
  std::copy_n(d.begin(), n, out.d._buffer);
  const double k[9] = {camera.fx_px, 0, camera.cx_px, 0, camera.fy_px, camera.cy_px, 0, 0, 1};
  std::copy(std::begin(k), std::end(k), out.k);
  const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::copy(std::begin(r), std::end(r), out.r);
  const double p[12] = {
      camera.fx_px, 0, camera.cx_px, 0, 0, camera.fy_px, camera.cy_px, 0, 0, 0, 1, 0};
  std::copy(std::begin(p), std::end(p), out.p);
  out.binning_x = 0;
  out.binning_y = 0;
  out.roi = {};
}

std::optional<geometry::CameraModel> from_camera_info(const msgs::sensor_msgs::CameraInfo& info,
                                                      std::string* why) {
  auto reject = [why](std::string text) -> std::optional<geometry::CameraModel> {
    if (why != nullptr) *why = "camera_info: " + std::move(text);
    return std::nullopt;
  };
  geometry::CameraModel camera;
  camera.width = static_cast<int>(std::min<std::uint32_t>(info.width, 1u << 20));
  camera.height = static_cast<int>(std::min<std::uint32_t>(info.height, 1u << 20));
  camera.fx_px = info.k[0];
  camera.cx_px = info.k[2];
  camera.fy_px = info.k[4];
  camera.cy_px = info.k[5];
  if (info.k[1] != 0 || info.k[3] != 0 || info.k[6] != 0 || info.k[7] != 0 || info.k[8] != 1) {
    return reject("K is not [fx 0 cx; 0 fy cy; 0 0 1] (skew is not supported)");
  }
  const std::string_view model = runtime::get_string(info.distortion_model);
  const std::span<const double> d(info.d._buffer, info.d._length);
  if (model == "plumb_bob" || model == "rational_polynomial" || (model.empty() && d.empty())) {
    const std::size_t expected = model == "rational_polynomial" ? 8 : 5;
    if (!d.empty() && d.size() != expected) {
      return reject("distortion_model '" + std::string(model) + "' needs " +
                    std::to_string(expected) + " coefficients in D, got " +
                    std::to_string(d.size()));
    }
    camera.set_distortion_coefficients(d);
  } else {
    return reject("distortion_model '" + std::string(model) +
                  "' (expected plumb_bob or rational_polynomial)");
  }
  if (info.binning_x > 1 || info.binning_y > 1) {
    return reject("binning " + std::to_string(info.binning_x) + "x" +
                  std::to_string(info.binning_y) + " is not supported");
  }
  if (info.roi.width != 0 && (info.roi.width != info.width || info.roi.height != info.height)) {
    return reject("a region of interest other than the full image is not supported");
  }
  if (std::string problem = camera.problem(); !problem.empty()) return reject(problem);
  return camera;
}

}  // namespace avs::msg
