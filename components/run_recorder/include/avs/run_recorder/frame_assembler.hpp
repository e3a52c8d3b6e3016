// Assembles one report row (avs::report::FrameRow) per depth update from the pieces that
// arrive on different topics with the depth image's stamp: ground truth (sim_scene), target
// observation (tracking), match result and world pose (matching), stage timings (/timing).
// No DDS here: the component feeds it, tests drive it directly.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "avs/geometry/camera_model.hpp"
#include "avs/report/run_data.hpp"

namespace avs::run_recorder {

/// The simulator's truth at one frame stamp.
struct Truth {
  report::Pose world;
  Eigen::Vector3d p_camera_m = Eigen::Vector3d::Zero();  ///< object origin, camera frame
  double pan_rad = 0;
  double tilt_rad = 0;
};

/// The object origin is in front of the camera and projects inside its image (ground-truth
/// "in view"), lens distortion included.
[[nodiscard]] bool in_view(const geometry::CameraModel& camera, const Eigen::Vector3d& p_camera_m);

struct AssemblerStats {
  std::uint64_t rows_written = 0;
  std::uint64_t rows_without_truth = 0;  ///< depth updates whose stamp had no ground truth
  std::uint64_t poses = 0;
};

class FrameAssembler {
 public:
  using RowSink = std::function<void(const report::FrameRow&)>;

  /// Rows are complete once `settle_updates` newer depth updates have arrived (the pieces of
  /// one update arrive within the same sim-time step in lockstep; 2 leaves a margin).
  explicit FrameAssembler(RowSink sink, int settle_updates = 2);

  /// The camera model in force (/depth/camera_info). Until it is known, rows have no
  /// in-view flag set and no centroid.
  void set_camera(const geometry::CameraModel& camera) { camera_ = camera; }

  void on_truth(std::int64_t stamp_ns, const Truth& truth);
  void on_depth(std::int64_t stamp_ns);
  void on_target(std::int64_t stamp_ns, bool valid, double u_px, double v_px);
  void on_match(std::int64_t stamp_ns, report::MatchState state, int scene_points,
                double processing_ms);
  void on_pose_world(std::int64_t stamp_ns, const report::Pose& pose);
  void on_timing(std::int64_t stamp_ns, const std::string& stage, double ms);

  /// Writes every pending row (end of run).
  void flush();
  [[nodiscard]] const AssemblerStats& stats() const { return stats_; }

 private:
  struct Pending {
    report::FrameRow row;
    bool depth_seen = false;
  };
  Pending& pending(std::int64_t stamp_ns);
  void emit(std::int64_t stamp_ns, Pending& p);
  void emit_settled();

  std::optional<geometry::CameraModel> camera_;
  RowSink sink_;
  int settle_updates_;
  std::map<std::int64_t, Pending> pending_;
  std::map<std::int64_t, Truth> truth_;
  std::deque<std::int64_t> depth_stamps_;
  std::int64_t last_emitted_ns_ = INT64_MIN;
  AssemblerStats stats_;
};

}  // namespace avs::run_recorder
