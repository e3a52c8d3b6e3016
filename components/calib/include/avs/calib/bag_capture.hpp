// Adapter: a recording of the rig's camera as a calibration capture source (issue 14 section 2,
// `avs calib capture --source bag`). The bag holds /camera/image_raw (sensor_msgs/Image, mono8)
// of a whole calibration session: the projector looping projection_sequence() (the `projector`
// component with `pattern_count` and `first_flash_image` of `avs calib patterns`), the camera
// publishing every frame (`image_raw_rate_hz` above its frame rate), the board moved through
// its poses (launch_config/calib_record.yaml). Frames get ids from their stamps
// (StampedFrameIds), ViewAssembler finds the checked cycles, and every cycle of a new pose
// (is_new_pose against every view taken) is one view.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "avs/calib/view_assembler.hpp"

namespace avs::calib {

struct BagCaptureConfig {
  std::string topic = "/camera/image_raw";
  /// Patterns per second; 0: from the recording (the median stamp step of its first frames).
  double rate_hz = 0;
  AssemblerConfig assembler;
  double min_new_pose_fraction = 0.02;  ///< as CameraCaptureConfig's
  int dds_domain = 0;                   ///< for the type's serialiser only (nothing is sent)
};

struct BagCaptureStats {
  std::int64_t messages = 0;
  std::int64_t off_grid = 0;    ///< frames whose stamp step is not whole periods
  std::int64_t bad_images = 0;  ///< not mono8, or sizes that do not agree
  std::int64_t same_pose = 0;   ///< checked cycles of a pose already taken
  std::int64_t rejected_cycles = 0;
  std::int64_t views = 0;
  double period_ms = 0;
  int width = 0;  ///< of the first image
  int height = 0;
};

/// Reads `file` to its end; calls `on_view` for each view (named by the caller), `log` for
/// every reason a frame or a cycle was not used (once per reason in a row) and for progress.
/// Throws std::runtime_error naming the file when it cannot be read, lacks the topic, or the
/// topic is not a sensor_msgs/Image.
BagCaptureStats capture_from_bag(const std::filesystem::path& file, const CaptureCodes& codes,
                                 const BagCaptureConfig& config,
                                 const std::function<void(BoardView&&)>& on_view,
                                 const std::function<void(const std::string&)>& log);

}  // namespace avs::calib
