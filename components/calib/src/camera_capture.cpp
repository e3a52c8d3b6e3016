#include "avs/calib/camera_capture.hpp"

#include <stdexcept>
#include <thread>

#include "aravis_camera.hpp"

namespace avs::calib {

using Clock = std::chrono::steady_clock;

struct CameraCapture::Camera {
  explicit Camera(const camera::CameraConfig& config) : device(config) {}
  camera::AravisCamera device;
};

projector::SequenceConfig calibration_sequence(const CaptureCodes& codes, int pattern_rate_hz,
                                               int first_flash_image) {
  if (pattern_rate_hz < 1 || 1000000 % pattern_rate_hz != 0) {
    throw std::invalid_argument("calib: pattern rate " + std::to_string(pattern_rate_hz) +
                                " Hz is not a whole number of microseconds per pattern");
  }
  projector::SequenceConfig sequence;
  sequence.pattern_count = static_cast<int>(projection_sequence(codes).size());
  sequence.frame_period_us = 1000000 / pattern_rate_hz;
  sequence.exposure_us = sequence.frame_period_us;
  sequence.first_flash_image = first_flash_image;
  sequence.repeat = true;
  return sequence;
}

CameraCapture::CameraCapture(CameraCaptureConfig config,
                             projector::TransportOpener projector_opener, const CaptureCodes& codes,
                             Log log)
    : config_(std::move(config)), codes_(codes), log_(std::move(log)) {
  if (config_.projector) {
    projector_ =
        std::make_unique<projector::ProjectorLink>(*config_.projector, std::move(projector_opener));
    const Clock::time_point until = Clock::now() + config_.projector_start_timeout;
    while (true) {
      for (const projector::LinkEvent& e : projector_->step(Clock::now()))
        log_("projector: " + e.text);
      if (projector_->state() == projector::LinkState::kRunning) break;
      if (projector_->state() == projector::LinkState::kRefused) {
        throw std::runtime_error(
            "projector refused the calibration sequence: " + projector_->validation_words() +
            " (are the calibration patterns in its flash? avs calib patterns)");
      }
      if (Clock::now() > until) {
        throw std::runtime_error("no projector within " +
                                 std::to_string(config_.projector_start_timeout.count()) +
                                 " ms: " + projector_->last_error());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  camera_ = std::make_unique<Camera>(config_.camera);
  camera_->device.start();
}

CameraCapture::~CameraCapture() {
  if (camera_) camera_->device.stop();
  if (projector_) {
    for (const projector::LinkEvent& e : projector_->close()) log_("projector: " + e.text);
  }
}

std::string CameraCapture::description() const {
  std::string text = "camera: " + camera_->device.description();
  if (const std::string untested = camera_->device.untested_path(); !untested.empty()) {
    text += "\nWARNING: " + untested;
  }
  text += projector_
              ? "\nprojector: " + projector_->device_description() + " (calibration sequence of " +
                    std::to_string(config_.projector->sequence.pattern_count) +
                    " patterns from flash image " +
                    std::to_string(config_.projector->sequence.first_flash_image) + ")"
              : "\nprojector: not controlled (it must be looping the calibration sequence)";
  return text;
}

void CameraCapture::step_projector() {
  if (!projector_) return;
  for (const projector::LinkEvent& e : projector_->step(Clock::now())) log_("projector: " + e.text);
}

std::optional<BoardView> CameraCapture::capture_view(
    const std::string& name, const std::vector<decode::GrayImage8>& taken_whites) {
  ViewAssembler assembler(codes_, config_.camera.width, config_.camera.height, config_.assembler);
  const Clock::time_point start = Clock::now();
  const Clock::time_point settled = start + config_.settle;
  const Clock::time_point until = settled + config_.view_timeout;
  std::string last_rejection;
  int rejections = 0;
  while (Clock::now() < until) {
    step_projector();
    std::optional<camera::CapturedFrame> frame =
        camera_->device.next(std::chrono::milliseconds(100));
    if (!frame) continue;
    if (!frame->complete) {
      // An incomplete frame breaks the run of ids: the assembler starts again after it.
      assembler.reset();
      ++rejections;
      last_rejection =
          "incomplete frame " + std::to_string(frame->frame_id) + " (" + frame->status + ")";
      continue;
    }
    // Frames exposed before the board was placed still come out of the buffers.
    if (Clock::now() < settled) continue;
    const decode::ImageView8 image{frame->data, frame->width, frame->height, frame->stride};
    AssemblerResult result = assembler.push(frame->frame_id, image);
    if (!result.rejected.empty()) {
      ++rejections;
      if (result.rejected != last_rejection) log_(name + ": " + result.rejected);
      last_rejection = result.rejected;
    }
    if (result.view &&
        !is_new_pose(*result.view, taken_whites, config_.assembler.moved_threshold_dn,
                     config_.min_new_pose_fraction)) {
      result.rejected = "a pose taken already: waiting for the board to move";
      if (result.rejected != last_rejection) log_(name + ": " + result.rejected);
      last_rejection = result.rejected;
      ++rejections;
      continue;
    }
    if (result.view) {
      result.view->name = name;
      return std::move(result.view);
    }
  }
  log_(name + ": no checked view within " + std::to_string(config_.view_timeout.count()) + " ms (" +
       std::to_string(assembler.frames_pushed()) + " frames, " + std::to_string(rejections) +
       " rejections; last: " + (last_rejection.empty() ? "none, too few frames" : last_rejection) +
       ")");
  return std::nullopt;
}

}  // namespace avs::calib
