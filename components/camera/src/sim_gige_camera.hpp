// A GigE Vision camera served from this process through Aravis's GV fake camera
// (arv_gv_fake_camera_new_full: GVCP on <interface>:3956, GVSP to whoever opens it), whose
// fill-pattern callback (arv_fake_camera_set_fill_pattern) asks `render` for frame k and
// stamps it with the camera frame id of k (16-bit GigE ids from first_frame_id, 0 skipped)
// and the timestamp (k + 1) / frame_rate_hz (an ideal triggered camera's clock) or the host
// clock. Frames in drop_frames are skipped: their ids never appear. The fake camera only
// free-runs (its hardware-trigger mode sends nothing). No Aravis or glib types here.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>

namespace avs::camera {

struct SimGigECameraConfig {
  std::string interface = "127.0.0.1";  ///< name or IPv4 address
  std::string serial = "AVSSIM01";
  double frame_rate_hz = 1000;
  std::uint64_t first_frame_id = 1;
  std::set<std::uint64_t> drop_frames;
  bool host_timestamps = false;  ///< false: (k + 1) / frame_rate_hz
  double lost_packet_ratio = 0;  ///< needs Aravis > 0.8.26 (refused otherwise)
};

class SimGigECamera {
 public:
  /// Writes frame k (Mono8, width x height, row-major) to `out`; runs on the fake camera's
  /// thread.
  using Render = std::function<void(std::uint64_t k, std::uint8_t* out)>;

  /// Starts serving; throws std::runtime_error when the interface or port is unavailable.
  SimGigECamera(SimGigECameraConfig config, int width, int height, Render render);
  ~SimGigECamera();
  SimGigECamera(const SimGigECamera&) = delete;
  SimGigECamera& operator=(const SimGigECamera&) = delete;

  std::uint64_t frames_sent() const { return filled_.load(); }
  std::uint64_t frames_skipped() const { return skipped_.load(); }
  /// Frames asked for with another ROI or pixel format than width x height Mono8 (sent black).
  std::uint64_t frames_mismatched() const { return mismatched_.load(); }

 private:
  struct Impl;
  void fill(void* buffer, bool mono8);  ///< an ArvBuffer*

  SimGigECameraConfig config_;
  int width_;
  int height_;
  Render render_;
  std::uint64_t next_ = 0;  ///< fake camera thread only
  std::atomic<std::uint64_t> filled_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<std::uint64_t> mismatched_{0};
  std::unique_ptr<Impl> impl_;  ///< last: the fake camera stops before the rest goes
};

}  // namespace avs::camera
