// Report rows from the topics of one depth update (see frame_assembler.hpp).
#include "avs/run_recorder/frame_assembler.hpp"

#include <cmath>
#include <cstdlib>

namespace avs::run_recorder {

namespace {
/// Ground truth is published per camera frame (1 kHz) with the frame's stamp, and a depth
/// update carries the stamp of its newest frame: they match exactly. A truth within this
/// tolerance is accepted for recordings whose stamps were rounded.
constexpr std::int64_t kTruthToleranceNs = 100'000;
}  // namespace

bool in_view(const geometry::CameraModel& camera, const Eigen::Vector3d& p) {
  if (!(p.z() > 0.0)) return false;
  return camera.contains(camera.project(p));
}

FrameAssembler::FrameAssembler(RowSink sink, int settle_updates)
    : sink_(std::move(sink)), settle_updates_(settle_updates) {}

FrameAssembler::Pending& FrameAssembler::pending(std::int64_t stamp_ns) {
  auto [it, inserted] = pending_.try_emplace(stamp_ns);
  if (inserted) it->second.row.t_s = static_cast<double>(stamp_ns) * 1e-9;
  return it->second;
}

void FrameAssembler::on_truth(std::int64_t stamp_ns, const Truth& truth) {
  if (stamp_ns <= last_emitted_ns_) return;
  truth_[stamp_ns] = truth;
}

void FrameAssembler::on_depth(std::int64_t stamp_ns) {
  if (stamp_ns <= last_emitted_ns_) return;  // late or repeated: its row is written
  Pending& p = pending(stamp_ns);
  if (p.depth_seen) return;
  p.depth_seen = true;
  depth_stamps_.push_back(stamp_ns);
  emit_settled();
}

void FrameAssembler::on_target(std::int64_t stamp_ns, bool valid, double u_px, double v_px) {
  if (stamp_ns <= last_emitted_ns_) return;
  report::FrameRow& row = pending(stamp_ns).row;
  if (valid && camera_) {
    // FrameRow wants the centroid relative to the image centre (Fig. 8's error).
    row.centroid_px = Eigen::Vector2d(u_px - camera_->cx_px, v_px - camera_->cy_px);
  } else {
    row.centroid_px.reset();
  }
}

void FrameAssembler::on_match(std::int64_t stamp_ns, report::MatchState state, int scene_points,
                              double processing_ms) {
  if (stamp_ns <= last_emitted_ns_) return;
  report::FrameRow& row = pending(stamp_ns).row;
  row.match_state = state;
  row.scene_points = scene_points;
  row.matching_ms = processing_ms;
}

void FrameAssembler::on_pose_world(std::int64_t stamp_ns, const report::Pose& pose) {
  if (stamp_ns <= last_emitted_ns_) return;
  pending(stamp_ns).row.meas = pose;
}

void FrameAssembler::on_timing(std::int64_t stamp_ns, const std::string& stage, double ms) {
  if (stamp_ns <= last_emitted_ns_) return;
  report::FrameRow& row = pending(stamp_ns).row;
  if (stage == "decode") {
    row.decode_ms = ms;
  } else if (stage == "tracking") {
    row.tracking_ms = ms;
  }
  // "matching" comes with the match result; "render" is the simulator's, not a stage of ours.
}

void FrameAssembler::emit(std::int64_t stamp_ns, Pending& p) {
  last_emitted_ns_ = stamp_ns;
  auto truth = truth_.lower_bound(stamp_ns - kTruthToleranceNs);
  if (truth == truth_.end() || std::llabs(truth->first - stamp_ns) > kTruthToleranceNs) {
    ++stats_.rows_without_truth;
  } else {
    report::FrameRow& row = p.row;
    row.truth = truth->second.world;
    row.in_view = camera_ && in_view(*camera_, truth->second.p_camera_m);
    row.pan_rad = truth->second.pan_rad;
    row.tilt_rad = truth->second.tilt_rad;
    // A pose only counts with a match state that has one.
    if (row.match_state != report::MatchState::tracking &&
        row.match_state != report::MatchState::init) {
      row.meas.reset();
    }
    if (row.meas) ++stats_.poses;
    sink_(row);
    ++stats_.rows_written;
  }
  // Everything up to this stamp is done.
  truth_.erase(truth_.begin(), truth_.upper_bound(stamp_ns));
}

void FrameAssembler::emit_settled() {
  while (static_cast<int>(depth_stamps_.size()) > settle_updates_) {
    const std::int64_t stamp = depth_stamps_.front();
    depth_stamps_.pop_front();
    // Pieces of stamps that never got a depth image (should not happen) are dropped.
    for (auto it = pending_.begin(); it != pending_.end() && it->first <= stamp;) {
      if (it->first == stamp) emit(stamp, it->second);
      it = pending_.erase(it);
    }
  }
}

void FrameAssembler::flush() {
  settle_updates_ = 0;
  emit_settled();
}

}  // namespace avs::run_recorder
