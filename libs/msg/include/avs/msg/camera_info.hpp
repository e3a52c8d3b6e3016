// sensor_msgs/CameraInfo <-> geometry::CameraModel, in ROS's conventions (REP 104): K row-major,
// D in OpenCV order with distortion_model "plumb_bob" or "rational_polynomial", R identity and
// P = [K | 0] for a monocular camera, no binning, full-image ROI.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "avs/geometry/camera_model.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/qos.hpp"

namespace avs::msg {

/// QoS of /depth/camera_info, publisher and subscribers alike: reliable, transient local, keep
/// last 1 (latched), so a consumer that starts later still gets the model before any image.
inline runtime::QosProfile camera_info_qos() {
  return *runtime::QosProfile::named("transient_local");
}

/// Fills `out` (its header's frame_id and the stamp are the caller's).
void to_camera_info(const geometry::CameraModel& camera, msgs::sensor_msgs::CameraInfo& out);

/// The camera model of a CameraInfo, or nullopt with `why` set (unknown distortion model, wrong
/// D length, non-positive size or focal length, binning or ROI that avs does not apply).
std::optional<geometry::CameraModel> from_camera_info(const msgs::sensor_msgs::CameraInfo& info,
                                                      std::string* why = nullptr);

}  // namespace avs::msg
