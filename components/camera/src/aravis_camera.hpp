// A GenICam camera through Aravis 0.8: open (by id or the only one found), configure the
// features of CameraConfig with one-line errors, stream into a fixed pool of buffers. Frames
// are lent: a CapturedFrame's lease keeps its buffer out of the stream while anyone holds it;
// the next call to next() after the last holder let go returns it (no copy, and no allocation
// per frame after each buffer's first use). No Aravis or glib types in this header.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "avs/camera/camera_config.hpp"

namespace avs::camera {

struct CapturedFrame {
  const std::uint8_t* data = nullptr;  ///< Mono8, `stride` bytes per row
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride = 0;
  std::size_t size = 0;  ///< bytes of image data
  std::uint64_t frame_id = 0;
  std::int64_t camera_timestamp_ns = 0;
  std::int64_t host_timestamp_ns = 0;  ///< host realtime clock when the buffer completed
  bool complete = false;
  const char* status = "";            ///< Aravis buffer status ("success", "missing packets", ...)
  std::shared_ptr<const void> lease;  ///< keeps the buffer out of the pool while held
};

/// Aravis stream statistics (GigE Vision names; zero where the transport has none).
struct StreamCounters {
  std::uint64_t completed = 0;
  std::uint64_t failures = 0;
  std::uint64_t underruns = 0;  ///< a frame arrived while no buffer was free (back-pressure)
  std::uint64_t timeouts = 0;
  std::uint64_t missing_frames = 0;
  std::uint64_t resent_packets = 0;
  std::uint64_t missing_packets = 0;
  std::uint64_t resend_requests = 0;
};

/// One line per camera Aravis sees: "<id> (<vendor> <model>, serial <s>, <address>)".
std::vector<std::string> list_cameras();

class AravisCamera {
 public:
  /// Opens and configures the camera; throws std::runtime_error with one line naming the
  /// feature, the value and what the camera allows, or the cameras found.
  explicit AravisCamera(const CameraConfig& config);
  ~AravisCamera();
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  /// What was opened and set, for the start-up log.
  const std::string& description() const;
  bool is_gige() const;
  /// What avs's own tests do not exercise on this camera's path (empty: the loopback GigE
  /// Vision path of the tests), for a start-up warning.
  std::string untested_path() const;

  void start();
  void stop();
  /// Writes ExposureTime (exposure_us > 0) and Gain (gain >= 0) while the camera streams (the
  /// camera component's live parameters); 0 and -1 write nothing. Throws std::runtime_error
  /// with the one line of a refused configuration (feature, value, what the camera allows);
  /// a refused value changes nothing on the camera. Not thread-safe against itself.
  void set_exposure_and_gain(double exposure_us, double gain);
  /// The next buffer (complete or not), or nothing after `timeout` (0: only what is there).
  /// First returns to the stream every buffer whose frames nobody holds any more; with
  /// (nearly) every buffer held it waits in 1 ms steps and does so between them. Call from one
  /// thread.
  std::optional<CapturedFrame> next(std::chrono::milliseconds timeout);
  /// Called on next()'s thread before each of its steps: whoever keeps frames' leases in
  /// samples of their own (runtime::LentSamplePool) lets go of the unused ones there, so that
  /// a buffer let go while next() waits comes back within a step. Set before streaming.
  void set_release_hook(std::function<void()> hook) { release_hook_ = std::move(hook); }
  StreamCounters counters() const;

 private:
  struct Impl;
  struct Lease;
  /// Returns released buffers to the stream; how many are still held.
  int return_released_buffers();
  const std::shared_ptr<Lease>& lease_of(void* buffer);

  std::shared_ptr<Impl> impl_;
  std::function<void()> release_hook_;
  /// One per stream buffer, made at its first frame: a frame's lease aliases it, so lending a
  /// frame allocates nothing.
  std::vector<std::shared_ptr<Lease>> leases_;
};

}  // namespace avs::camera
