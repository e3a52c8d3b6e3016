// What a consumer of /depth/camera_info keeps (tracking, matching): the newest valid camera
// model, a log line when it changes, a rejection for an unusable message, and the check that a
// depth image fits it. One copy instead of one per component.
#pragma once

#include <optional>
#include <string>

#include "avs/geometry/camera_model.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/logger.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::msg {

class CameraInput {
 public:
  CameraInput(const runtime::Logger& log, runtime::SampleRejections& rejected)
      : log_(log), rejected_(rejected) {}

  /// Takes one CameraInfo; true when the model changed (the first one, or a different one).
  /// An unusable message is rejected (counted, logged) and the previous model kept.
  bool update(const msgs::sensor_msgs::CameraInfo& info);

  /// The model in force, if any has come.
  const std::optional<geometry::CameraModel>& model() const { return model_; }

  /// Whether a depth image of this size can be used now; if not, rejects it with the reason
  /// (no camera_info yet, or another size) and returns false.
  bool accepts_image(int width, int height);

 private:
  const runtime::Logger& log_;
  runtime::SampleRejections& rejected_;
  std::optional<geometry::CameraModel> model_;
};

}  // namespace avs::msg
