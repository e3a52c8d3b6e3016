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
  // GigE Vision block ids are 16 bits with 0 skipped; USB3 Vision's are 64 bits.
  config_.assembler.frame_id_bits = camera_->device.is_gige() ? 16 : 64;
  config_.assembler.frame_id_zero_skipped = camera_->device.is_gige();
  camera_->device.start();
}

CameraCapture::~CameraCapture() {
  // A camera that left the network refuses AcquisitionStop: said, and the projector still
  // stopped (a destructor must not throw).
  try {
    if (camera_) camera_->device.stop();
  } catch (const std::exception& e) {
    log_(std::string("camera: stopping: ") + e.what());
  }
  if (projector_) {
    try {
      for (const projector::LinkEvent& e : projector_->close()) log_("projector: " + e.text);
    } catch (const std::exception& e) {
      log_(std::string("projector: stopping: ") + e.what());
    }
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
  RepeatedReasons reasons([this, &name](const std::string& line) { log_(name + ": " + line); });
  while (Clock::now() < until && !(config_.interrupted && config_.interrupted())) {
    step_projector();
    std::optional<camera::CapturedFrame> frame =
        camera_->device.next(std::chrono::milliseconds(100));
    if (!frame) continue;
    if (!frame->complete) {
      // An incomplete frame breaks the run of ids: the assembler starts again after it.
      assembler.reset();
      reasons.add(std::string("incomplete frame (") + frame->status + ")");
      continue;
    }
    // Frames exposed before the board was placed still come out of the buffers.
    if (Clock::now() < settled) continue;
    const decode::ImageView8 image{frame->data, frame->width, frame->height, frame->stride};
    AssemblerResult result = assembler.push(frame->frame_id, image);
    if (!result.rejected.empty()) reasons.add(result.rejected);
    if (result.view &&
        !is_new_pose(*result.view, taken_whites, config_.assembler.moved_threshold_dn,
                     config_.min_new_pose_fraction)) {
      reasons.add("a pose taken already: waiting for the board to move");
      continue;
    }
    if (result.view) {
      reasons.flush();
      result.view->name = name;
      return std::move(result.view);
    }
  }
  reasons.flush();
  log_(name + ": no checked view " +
       (Clock::now() < until ? std::string("(interrupted)")
                             : "within " + std::to_string(config_.view_timeout.count()) + " ms") +
       " (" + std::to_string(assembler.frames_pushed()) + " frames, " +
       std::to_string(reasons.total()) + " rejections; last: " +
       (reasons.last().empty() ? "none, too few frames" : reasons.last()) + ")");
  return std::nullopt;
}

}  // namespace avs::calib
