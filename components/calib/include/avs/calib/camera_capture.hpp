// Adapter: the rig's camera and projector as a calibration capture source (issue 14 section 2,
// `avs calib capture --source camera`). The projector (a DLPC350 through projector::ProjectorLink,
// or none when the lab runs it by other means) loops the calibration sequence of
// projection_sequence() from its flash (`avs calib patterns` writes the images), one camera trigger
// per pattern; the camera (Aravis: GigE Vision or USB3 Vision) streams; ViewAssembler finds the
// sequence in the frames. capture_view() is called once per board pose, while the board is
// held still. Tested over the real GigE Vision stack against the simulator served by Aravis's
// GV fake camera, with the projector on avs's DLPC350 emulator (tests/calib).
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "avs/calib/view_assembler.hpp"
#include "avs/camera/camera_config.hpp"
#include "avs/projector/hid_transport.hpp"
#include "avs/projector/projector_link.hpp"

namespace avs::calib {

struct CameraCaptureConfig {
  camera::CameraConfig camera;
  /// The projector's link with the calibration sequence (calibration_sequence()); nullopt:
  /// the projector is already looping it (the capture does not touch it).
  std::optional<projector::LinkConfig> projector;
  AssemblerConfig assembler;
  std::chrono::milliseconds settle{300};  ///< frames dropped after the board was placed
  std::chrono::milliseconds view_timeout{10000};
  /// A new pose changes at least this fraction of the white frame's pixels (by more than
  /// assembler.moved_threshold_dn).
  double min_new_pose_fraction = 0.02;
  /// Polled while waiting for a view: true ends the wait (Ctrl-C); empty: never.
  std::function<bool()> interrupted;
  std::chrono::milliseconds projector_start_timeout{5000};
};

/// The DLPC350 sequence of the calibration frames: projection_sequence(codes) in order, one flash
/// bit plane each from `first_flash_image` on (`avs calib patterns` packs them so), looped.
projector::SequenceConfig calibration_sequence(const CaptureCodes& codes, int pattern_rate_hz,
                                               int first_flash_image);

class CameraCapture {
 public:
  using Log = std::function<void(const std::string& line)>;

  /// Opens the camera and starts the projector's sequence; throws std::runtime_error with the
  /// camera's or the projector's one-line reason (no camera, a refused sequence, no projector
  /// within projector_start_timeout).
  CameraCapture(CameraCaptureConfig config, projector::TransportOpener projector_opener,
                const CaptureCodes& codes, Log log);
  ~CameraCapture();
  CameraCapture(const CameraCapture&) = delete;
  CameraCapture& operator=(const CameraCapture&) = delete;

  /// The frames of one board pose: drops `settle` worth of frames, then assembles a checked
  /// cycle. A view whose white frame differs from one of `taken_whites` (the white frames of the
  /// views taken) in less than `min_new_pose_fraction` of the pixels is a pose taken already:
  /// skipped, and the capture waits for the board to move. Returns nullopt after
  /// `view_timeout` or when `interrupted` says so (the rejections logged, each reason once in a
  /// row with its count).
  std::optional<BoardView> capture_view(const std::string& name,
                                        const std::vector<decode::GrayImage8>& taken_whites = {});

  int width() const { return config_.camera.width; }
  int height() const { return config_.camera.height; }
  /// What was opened, for the start-up lines.
  std::string description() const;

 private:
  void step_projector();

  CameraCaptureConfig config_;
  CaptureCodes codes_;
  Log log_;
  std::unique_ptr<projector::ProjectorLink> projector_;
  struct Camera;
  std::unique_ptr<Camera> camera_;
};

}  // namespace avs::calib
