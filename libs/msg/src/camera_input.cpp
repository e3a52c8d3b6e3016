#include "avs/msg/camera_input.hpp"

#include "avs/msg/camera_info.hpp"

namespace avs::msg {

bool CameraInput::update(const msgs::sensor_msgs::CameraInfo& info) {
  std::string why;
  auto camera = from_camera_info(info, &why);
  if (!camera) {
    rejected_.reject(why);
    return false;
  }
  if (model_ && *model_ == *camera) return false;
  log_.info("camera model from /depth/camera_info: ", camera->width, "x", camera->height, ", f ",
            camera->fx_px, " / ", camera->fy_px, " px, c ", camera->cx_px, " / ", camera->cy_px,
            " px, ", camera->distortion_model(),
            camera->has_distortion() ? " with distortion" : " without distortion");
  model_ = *camera;
  return true;
}

bool CameraInput::accepts_image(int width, int height) {
  if (!model_) {
    // Decode latches its camera_info before the first image: none means no camera model.
    rejected_.reject("depth image before any /depth/camera_info");
    return false;
  }
  if (width != model_->width || height != model_->height) {
    rejected_.reject("depth image " + std::to_string(width) + "x" + std::to_string(height) +
                     ", /depth/camera_info says " + std::to_string(model_->width) + "x" +
                     std::to_string(model_->height));
    return false;
  }
  return true;
}

}  // namespace avs::msg
