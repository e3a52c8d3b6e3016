// run_recorder: writes a run folder (docs/report.md) from the topics of a simulated run:
// /sim/ground_truth, /depth/image, /target, /object/match, /object/pose_world, /object/pose,
// /object/scene_points and /timing. One row per depth update, a depth snapshot (Figure 9)
// and scene/model cloud snapshots (Figure 14). `avs demo` and `avs experiments` host it in
// the simulation's container and read its progress.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "avs/msg/camera_input.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/run_recorder/frame_assembler.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::run_recorder {

/// Counters a progress display may read from another thread.
struct RecorderProgress {
  std::atomic<std::uint64_t> frames{0};         ///< ground-truth frames (camera frames)
  std::atomic<std::uint64_t> depth_updates{0};  ///< /depth/image samples
  std::atomic<std::uint64_t> poses{0};          ///< /object/pose_world samples
  std::atomic<std::uint64_t> targets_valid{0};  ///< /target samples with a target
  std::atomic<std::int64_t> last_stamp_ns{0};   ///< newest depth stamp
};

class RunRecorderComponent final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec();
  explicit RunRecorderComponent(runtime::ComponentContext& ctx);
  ~RunRecorderComponent() override;

  void on_deactivate() override;
  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override;

  [[nodiscard]] const RecorderProgress& progress() const { return progress_; }

 private:
  void on_depth(const msgs::sensor_msgs::Image& image);
  void on_depth_sample(runtime::SamplePtr<msgs::sensor_msgs::Image> image);
  void write_depth_snapshot(const msgs::sensor_msgs::Image& image);
  void on_pose_camera(const msgs::geometry_msgs::PoseStamped& pose);
  void on_scene_points(const msgs::sensor_msgs::PointCloud2& cloud);

  std::unique_ptr<report::RunRecorder> recorder_;
  std::unique_ptr<FrameAssembler> assembler_;
  RecorderProgress progress_;
  double depth_snapshot_time_s_ = 0;
  bool depth_snapshot_taken_ = false;
  runtime::SamplePtr<msgs::sensor_msgs::Image> last_depth_;
  std::string truth_object_;
  std::set<std::string> other_objects_;
  std::vector<double> cloud_times_s_;
  double cloud_period_s_ = 0.0;
  double next_periodic_cloud_s_ = 0.0;
  bool clouds_refused_ = false;  ///< a cloud that cannot be read stops the snapshots
  std::chrono::steady_clock::time_point wall_start_;
  std::size_t next_cloud_ = 0;
  std::vector<Eigen::Vector3d> model_points_m_;
  std::optional<std::pair<std::int64_t, Eigen::Isometry3d>> last_pose_camera_;
  bool finished_ = false;
  runtime::SampleRejections rejected_{log(), "input"};
  msg::CameraInput camera_{log(), rejected_};  ///< from /depth/camera_info
};

}  // namespace avs::run_recorder
