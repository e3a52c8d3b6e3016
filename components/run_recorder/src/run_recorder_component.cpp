// run_recorder (see run_recorder_component.hpp).
#include "avs/run_recorder/run_recorder_component.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/mesh.hpp"
#include "avs/matching/model_cloud.hpp"
#include "avs/msg/camera_info.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/runtime/time.hpp"

namespace avs::run_recorder {

using runtime::ParamSpec;

namespace {

std::int64_t stamp_ns(const msgs::builtin_interfaces::Time& t) {
  return runtime::from_ros_time(t).ns;
}

report::Pose to_pose(const msgs::geometry_msgs::Pose& p) {
  const Eigen::Isometry3d T = msg::to_isometry(p);
  report::Pose out;
  out.p_world_m = T.translation();
  out.q_world = Eigen::Quaterniond(T.linear());
  return out;
}

report::MatchState to_match_state(std::uint8_t state) {
  switch (state) {
    case avs_msgs_msg_dds__MatchResult_Constants_STATE_INITIALISING:
      return report::MatchState::init;
    case avs_msgs_msg_dds__MatchResult_Constants_STATE_TRACKING:
      return report::MatchState::tracking;
    case avs_msgs_msg_dds__MatchResult_Constants_STATE_LOST:
      return report::MatchState::lost;
    default:
      return report::MatchState::none;
  }
}

geometry::Mesh load_model(const std::string& model) {
  for (const auto& name : geometry::builtin_model_names()) {
    if (name == model) return geometry::make_builtin_model(model);
  }
  return geometry::load_mesh(model);
}

}  // namespace

runtime::ComponentSpec RunRecorderComponent::spec() {
  runtime::QosProfile deep;
  deep.depth = 100;
  return {
      .type = "run_recorder",
      .description =
          "writes a run folder (frames.csv, meta.csv, snapshots; docs/report.md) "
          "from ground truth, depth, target, match and timing topics",
      .parameters =
          {ParamSpec::string("dir", "", "run folder to write (required)"),
           ParamSpec::string("scenario", "demo", "scenario name written to meta.csv"),
           ParamSpec::string("object", "ken", "target model name written to meta.csv"),
           ParamSpec::string("symmetry", "none",
                             "symmetry for the orientation error: none, cube, cylinder_x|y|z"),
           ParamSpec::string("notes", "", "free text shown in the report"),
           ParamSpec::string("truth_object", "",
                             "object_name on /sim/ground_truth that is the target (the scene "
                             "publishes one message per object); empty: `object`"),
           ParamSpec::string("model", "",
                             "mesh drawn over the scene in the cloud snapshots (built-in name or "
                             "file); empty: `object`"),
           ParamSpec::real("depth_snapshot_time_s", 1.0, 0.0, 1e9, "s",
                           "the first depth image at or after this time is kept (Figure 9); "
                           "a shorter run keeps its last one"),
           ParamSpec::real_list("cloud_snapshot_times_s", {}, "s",
                                "scene/model snapshots (Figure 14) at these times"),
           ParamSpec::real("cloud_snapshot_period_s", 0.25, 0.0, 1e9, "s",
                           "and one snapshot every this much simulated time (0: none), so "
                           "that the report can spread Figure 14 over the whole run")},
      .publishes = {},
      .subscribes = {
          runtime::port<msgs::avs_msgs::GroundTruth>("ground_truth", "/sim/ground_truth", deep),
          runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image"),
          runtime::port<msgs::sensor_msgs::CameraInfo>("camera_info", "/depth/camera_info",
                                                       msg::camera_info_qos()),
          runtime::port<msgs::avs_msgs::TargetObservation>("target", "/target", deep),
          runtime::port<msgs::avs_msgs::MatchResult>("match", "/object/match", deep),
          runtime::port<msgs::geometry_msgs::PoseStamped>("pose_world", "/object/pose_world", deep),
          runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose", deep),
          runtime::port<msgs::sensor_msgs::PointCloud2>("scene_points", "/object/scene_points"),
          runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing", deep)}};
}

RunRecorderComponent::RunRecorderComponent(runtime::ComponentContext& ctx) : Component(ctx) {
  const auto dir = ctx.param<std::string>("dir");
  if (dir.empty()) throw std::invalid_argument("parameter 'dir' (the run folder) is required");
  report::RunInfo info;
  info.scenario = ctx.param<std::string>("scenario");
  info.object = ctx.param<std::string>("object");
  info.symmetry = ctx.param<std::string>("symmetry");
  info.notes = ctx.param<std::string>("notes");
  std::filesystem::create_directories(dir);
  recorder_ = std::make_unique<report::RunRecorder>(dir, info);

  // The wall clock beside the run's clock gives the report its real-time factor.
  wall_start_ = std::chrono::steady_clock::now();
  assembler_ = std::make_unique<FrameAssembler>([this](const report::FrameRow& row) {
    report::FrameRow timed = row;
    timed.wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    recorder_->write_frame(timed);
  });
  depth_snapshot_time_s_ = ctx.param<double>("depth_snapshot_time_s");
  cloud_times_s_ = ctx.param<std::vector<double>>("cloud_snapshot_times_s");
  std::sort(cloud_times_s_.begin(), cloud_times_s_.end());
  cloud_period_s_ = ctx.param<double>("cloud_snapshot_period_s");
  next_periodic_cloud_s_ = cloud_period_s_;

  std::string model = ctx.param<std::string>("model");
  if (model.empty()) model = info.object;
  if (!cloud_times_s_.empty() || cloud_period_s_ > 0.0) {
    try {
      matching::ModelCloudConfig config;
      config.target_points = 400;
      const auto cloud = matching::make_model_cloud(load_model(model), config);
      for (const auto& p : cloud.points_m) model_points_m_.push_back(p.cast<double>());
    } catch (const std::exception& e) {
      log().warn("no model cloud for the snapshots (", model, "): ", e.what());
    }
  }

  truth_object_ = ctx.param<std::string>("truth_object");
  if (truth_object_.empty()) truth_object_ = info.object;
  ctx.subscribe<msgs::avs_msgs::GroundTruth>(
      "ground_truth", [this](runtime::SamplePtr<msgs::avs_msgs::GroundTruth> m) {
        const std::string_view name = runtime::get_string(m->object_name);
        if (name != truth_object_) {
          if (other_objects_.size() < 16) other_objects_.insert(std::string(name));
          return;
        }
        Truth truth;
        truth.world = to_pose(m->pose_world);
        truth.p_camera_m = {m->pose_camera.position.x, m->pose_camera.position.y,
                            m->pose_camera.position.z};
        truth.pan_rad = m->pan_rad;
        truth.tilt_rad = m->tilt_rad;
        assembler_->on_truth(stamp_ns(m->header.stamp), truth);
        ++progress_.frames;
      });
  ctx.subscribe<msgs::sensor_msgs::CameraInfo>(
      "camera_info", [this](runtime::SamplePtr<msgs::sensor_msgs::CameraInfo> m) {
        if (camera_.update(*m)) {
          assembler_->set_camera(*camera_.model());  // the in-view test, the centroid's origin
        }
      });
  ctx.subscribe<msgs::sensor_msgs::Image>(
      "depth",
      [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth_sample(std::move(m)); });
  ctx.subscribe<msgs::avs_msgs::TargetObservation>(
      "target", [this](runtime::SamplePtr<msgs::avs_msgs::TargetObservation> m) {
        assembler_->on_target(stamp_ns(m->header.stamp), m->valid, m->centroid_x_px,
                              m->centroid_y_px);
        if (m->valid) ++progress_.targets_valid;
      });
  ctx.subscribe<msgs::avs_msgs::MatchResult>(
      "match", [this](runtime::SamplePtr<msgs::avs_msgs::MatchResult> m) {
        assembler_->on_match(stamp_ns(m->header.stamp), to_match_state(m->state),
                             static_cast<int>(m->scene_points), m->processing_time_ms);
      });
  ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
      "pose_world", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) {
        assembler_->on_pose_world(stamp_ns(m->header.stamp), to_pose(m->pose));
        ++progress_.poses;
      });
  ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
      "pose",
      [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) { on_pose_camera(*m); });
  ctx.subscribe<msgs::sensor_msgs::PointCloud2>(
      "scene_points",
      [this](runtime::SamplePtr<msgs::sensor_msgs::PointCloud2> m) { on_scene_points(*m); });
  ctx.subscribe<msgs::avs_msgs::StageTiming>(
      "timing", [this](runtime::SamplePtr<msgs::avs_msgs::StageTiming> m) {
        assembler_->on_timing(stamp_ns(m->header.stamp), std::string(runtime::get_string(m->stage)),
                              m->processing_ms);
      });
}

RunRecorderComponent::~RunRecorderComponent() {
  if (!finished_) {
    try {
      assembler_->flush();
      recorder_->flush();
    } catch (...) {  // a destructor must not throw; on_deactivate reports errors
    }
  }
}

void RunRecorderComponent::on_deactivate() {
  if (!depth_snapshot_taken_ && last_depth_) write_depth_snapshot(*last_depth_);
  if (progress_.frames.load() == 0) {
    std::string seen;
    for (const auto& name : other_objects_) seen += (seen.empty() ? "" : ", ") + name;
    log().error("no ground truth for object '", truth_object_,
                "' (set truth_object); seen: ", seen.empty() ? "none" : seen);
  }
  assembler_->flush();
  recorder_->flush();
  finished_ = true;
  const auto& s = assembler_->stats();
  log().info("run folder ", recorder_->dir().string(), ": ", s.rows_written, " depth updates, ",
             s.poses, " with a pose");
  if (s.rows_without_truth > 0) {
    log().warn(s.rows_without_truth,
               " depth updates had no ground truth with their stamp and are not in frames.csv");
  }
}

std::vector<std::pair<std::string, std::string>> RunRecorderComponent::diagnostic_values() const {
  return {rejected_.diagnostic()};
}

void RunRecorderComponent::on_depth(const msgs::sensor_msgs::Image& image) {
  const std::int64_t stamp = stamp_ns(image.header.stamp);
  assembler_->on_depth(stamp);
  ++progress_.depth_updates;
  progress_.last_stamp_ns = stamp;
}

void RunRecorderComponent::on_depth_sample(runtime::SamplePtr<msgs::sensor_msgs::Image> image) {
  on_depth(*image);
  const double t_s = runtime::from_ros_time(image->header.stamp).seconds();
  if (depth_snapshot_taken_) return;
  if (t_s < depth_snapshot_time_s_) {
    last_depth_ = std::move(image);  // shared, not copied
    return;
  }
  write_depth_snapshot(*image);
}

void RunRecorderComponent::write_depth_snapshot(const msgs::sensor_msgs::Image& image) {
  const double t_s = runtime::from_ros_time(image.header.stamp).seconds();
  if (runtime::get_string(image.encoding) != "32FC1" || image.step != image.width * 4 ||
      static_cast<std::uint64_t>(image.step) * image.height > image.data._length) {
    rejected_.reject("depth snapshot skipped: expected packed 32FC1, got '" +
                     std::string(runtime::get_string(image.encoding)) + "'");
    depth_snapshot_taken_ = true;
    return;
  }
  recorder_->write_depth_snapshot(
      t_s, static_cast<int>(image.width), static_cast<int>(image.height),
      std::span<const float>(reinterpret_cast<const float*>(image.data._buffer),
                             static_cast<std::size_t>(image.width) * image.height));
  depth_snapshot_taken_ = true;
}

void RunRecorderComponent::on_pose_camera(const msgs::geometry_msgs::PoseStamped& pose) {
  const report::Pose p = to_pose(pose.pose);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.q_world.toRotationMatrix();  // camera frame here, despite the field's name
  T.translation() = p.p_world_m;
  last_pose_camera_ = {stamp_ns(pose.header.stamp), T};
}

void RunRecorderComponent::on_scene_points(const msgs::sensor_msgs::PointCloud2& cloud) {
  if (clouds_refused_) return;
  const std::int64_t stamp = stamp_ns(cloud.header.stamp);
  const double t_s = static_cast<double>(stamp) * 1e-9;
  const bool listed_due = next_cloud_ < cloud_times_s_.size() && t_s >= cloud_times_s_[next_cloud_];
  const bool periodic_due = cloud_period_s_ > 0.0 && t_s >= next_periodic_cloud_s_;
  if (!listed_due && !periodic_due) return;
  // The model at the pose estimated from this very cloud (published before the cloud).
  if (!last_pose_camera_ || last_pose_camera_->first != stamp) return;
  std::string why;
  const auto points = msg::read_xyz_cloud(cloud, &why);
  if (!points) {
    rejected_.reject("cloud snapshots stopped: " + why);
    clouds_refused_ = true;
    return;
  }
  const std::vector<Eigen::Vector3d>& scene = *points;
  std::vector<Eigen::Vector3d> model;
  model.reserve(model_points_m_.size());
  for (const auto& p : model_points_m_) model.push_back(last_pose_camera_->second * p);
  if (scene.empty() && model.empty()) return;
  recorder_->write_cloud_snapshot(t_s, scene, model);
  while (next_cloud_ < cloud_times_s_.size() && cloud_times_s_[next_cloud_] <= t_s) ++next_cloud_;
  if (cloud_period_s_ > 0.0) {
    next_periodic_cloud_s_ = (std::floor(t_s / cloud_period_s_) + 1.0) * cloud_period_s_;
  }
}

AVS_REGISTER_COMPONENT(RunRecorderComponent);

}  // namespace avs::run_recorder
