#include "avs/matching/pipeline.hpp"

#include <chrono>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "avs/geometry/builtin_models.hpp"

namespace avs::matching {
namespace {

/// The settings the constructor and retune() both refuse: an empty depth window ("depth_min_m
/// (2) must be below depth_max_m (1.5)", the numbers as written) or lag settings out of range.
void check_settings(const PipelineConfig& config, const std::string& who) {
  if (!(config.depth_min_m < config.depth_max_m)) {
    std::ostringstream out;
    out << who << "depth_min_m (" << config.depth_min_m << ") must be below depth_max_m ("
        << config.depth_max_m << ")";
    throw std::invalid_argument(out.str());
  }
  if (config.lag_compensation_s < 0.0 || config.velocity_window_s <= 0.0) {
    throw std::invalid_argument(who + "lag_compensation_s must be >= 0 and velocity_window_s > 0");
  }
}

SceneCloudConfig scene_config(const PipelineConfig& config, const ModelCloud& model) {
  SceneCloudConfig scene = config.scene;
  scene.min_depth_m = config.depth_min_m;
  scene.max_depth_m = config.depth_max_m;
  // Same density in both clouds (section 6.3): r defaults to the M-PCD's voxel side.
  if (!(scene.voxel_size_m > 0.0F)) scene.voxel_size_m = model.voxel_size_m;
  return scene;
}

/// pose moved forward by dt_s at the motion that took `older` (at t_older) to `newer` (at
/// t_newer): constant linear and angular velocity in the camera frame.
Eigen::Isometry3f extrapolate(const Eigen::Isometry3f& older, double t_older,
                              const Eigen::Isometry3f& newer, double t_newer, double dt_s,
                              bool rotate) {
  if (!(t_newer > t_older)) return newer;
  const double scale = dt_s / (t_newer - t_older);
  const Eigen::Isometry3f delta = newer * older.inverse();  // older -> newer, camera frame
  const Eigen::AngleAxisf rotation(delta.linear());
  const Eigen::Matrix3f r =
      Eigen::AngleAxisf(rotation.angle() * static_cast<float>(scale), rotation.axis())
          .toRotationMatrix();
  // Rotate about the object's origin, translate its origin at the mean velocity.
  const Eigen::Vector3f v = (newer.translation() - older.translation()) * static_cast<float>(scale);
  Eigen::Isometry3f out = Eigen::Isometry3f::Identity();
  out.linear() = rotate ? Eigen::Matrix3f(r * newer.linear()) : newer.linear();
  out.translation() = newer.translation() + v;
  return out;
}

}  // namespace

MatchingPipeline::MatchingPipeline(ModelCloud model, PipelineConfig config)
    : model_(std::move(model)),
      config_(config),
      builder_(scene_config(config_, model_)),
      tracker_(model_, config_.tracker),
      scene_(&empty_) {
  check_settings(config_, "MatchingPipeline: ");
  history_.reserve(64);
}

void MatchingPipeline::retune(const PipelineConfig& config) {
  check_settings(config, "");
  config_.depth_min_m = config.depth_min_m;
  config_.depth_max_m = config.depth_max_m;
  builder_.set_depth_window(config.depth_min_m, config.depth_max_m);
  config_.lag_compensation_s = config.lag_compensation_s;
  config_.velocity_window_s = config.velocity_window_s;
  config_.max_border_pixels = config.max_border_pixels;
  config_.tracker.max_rmse_m = config.tracker.max_rmse_m;
  config_.tracker.min_inlier_ratio = config.tracker.min_inlier_ratio;
  config_.tracker.failures_before_loss = config.tracker.failures_before_loss;
  config_.tracker.min_scene_points = config.tracker.min_scene_points;
  config_.tracker.constant_velocity = config.tracker.constant_velocity;
  config_.tracker.reacquire_within_s = config.tracker.reacquire_within_s;
  tracker_.retune(config.tracker);
}

std::size_t MatchingPipeline::border_pixels(const DepthView& depth) const {
  const int w = depth.width_px;
  const int h = depth.height_px;
  const int stride = depth.stride_px > 0 ? depth.stride_px : w;
  if (w <= 0 || h <= 0 || depth.depth_m == nullptr) return 0;
  const auto in_window = [&](int u, int v) {
    const float z = depth.depth_m[static_cast<std::ptrdiff_t>(v) * stride + u];
    return z >= config_.depth_min_m && z <= config_.depth_max_m;  // NaN is false
  };
  std::size_t count = 0;
  for (int u = 0; u < w; ++u)
    count += (in_window(u, 0) ? 1 : 0) + (h > 1 && in_window(u, h - 1) ? 1 : 0);
  for (int v = 1; v + 1 < h; ++v)
    count += (in_window(0, v) ? 1 : 0) + (w > 1 && in_window(w - 1, v) ? 1 : 0);
  return count;
}

PipelineOutput MatchingPipeline::process(const DepthView& depth, double stamp_s) {
  return process(depth, stamp_s, -1.0);
}

PipelineOutput MatchingPipeline::process(const DepthView& depth, double stamp_s,
                                         double data_age_s) {
  const bool aged = data_age_s >= 0.0;
  const double lag_s = aged ? data_age_s : config_.lag_compensation_s;
  const double data_stamp_s = aged ? stamp_s - data_age_s : stamp_s;
  const auto start = std::chrono::steady_clock::now();
  PipelineOutput out;
  out.border_pixels = border_pixels(depth);
  out.truncated = config_.max_border_pixels >= 0 &&
                  out.border_pixels > static_cast<std::size_t>(config_.max_border_pixels);
  MaskView mask;
  if (out.truncated && config_.min_pixels_beside_border_clutter > 0) {
    // Clutter that enters from the side: match what is not connected to the border, if enough.
    const std::size_t clutter = border_regions_.mark(
        depth, config_.depth_min_m, config_.depth_max_m, config_.border_region_step_m);
    if (border_regions_.depth_separation_m() >= config_.border_clutter_min_separation_m) {
      out.border_clutter_pixels = clutter;
      mask.mask = border_regions_.keep_mask();
    }
  }
  scene_ = &builder_.build(depth, mask, config_.camera);
  out.valid_pixels = builder_.valid_pixels();
  out.scene_points = scene_->size();
  if (mask.mask != nullptr) {
    out.truncated =
        out.valid_pixels < static_cast<std::size_t>(config_.min_pixels_beside_border_clutter);
  }
  if (out.truncated) {
    // Partly out of view: no pose, and a fresh initial alignment once the target is whole.
    tracker_.reset();
    history_.clear();
    out.track.state = TrackingState::lost;
    out.processing_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return out;
  }
  out.track = tracker_.update(*scene_, stamp_s);
  out.has_pose = out.track.state == TrackingState::tracking;
  out.T_camera_model = out.track.T_camera_model;

  // Pose history for the velocity estimate: valid tracked poses only, within the window.
  if (out.track.state != TrackingState::tracking || out.track.initialised_this_frame ||
      out.track.reacquired_this_frame) {
    history_.clear();
  }
  if (out.track.pose_valid) {
    history_.push_back({data_stamp_s, out.track.T_camera_model});
    while (history_.size() > 2 && data_stamp_s - history_[1].stamp_s >= config_.velocity_window_s) {
      history_.erase(history_.begin());
    }
  }
  if (config_.lag_compensation_s > 0.0 && lag_s > 0.0 && out.has_pose && history_.size() >= 2) {
    const Stamped& older = history_.front();
    const Stamped& newer = history_.back();
    out.T_camera_model = extrapolate(older.T_camera_model, older.stamp_s, newer.T_camera_model,
                                     newer.stamp_s, lag_s, config_.lag_compensate_rotation);
    out.lag_compensated = true;
  }
  out.processing_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

ObjectModel load_object_model(const std::string& name_or_path, const std::string& models_dir) {
  ObjectModel object;
  struct Preset {
    const char* name;
    std::size_t model_points, scene_points;
    Symmetry symmetry;
  };
  // Section 7.2: M-PCD sizes 302 / 488 / 248 and i_number 250 / 350 / 300.
  static constexpr Preset presets[] = {{"ken", 302, 250, Symmetry::none},
                                       {"cube", 488, 350, Symmetry::cube},
                                       {"cylinder", 248, 300, Symmetry::cylinder_z}};
  object.name = name_or_path;
  object.model_points = 300;
  object.scene_points = 250;
  object.mesh_path = name_or_path;
  for (const Preset& preset : presets) {
    if (name_or_path != preset.name) continue;
    object.model_points = preset.model_points;
    object.scene_points = preset.scene_points;
    object.symmetry = preset.symmetry;
    if (preset.symmetry == Symmetry::cylinder_z) object.metric = IcpMetric::point_to_point;
    object.mesh_path = (models_dir.empty() ? geometry::default_models_dir() : models_dir) + "/" +
                       preset.name + ".ply";
  }
  if (object.mesh_path == name_or_path) {
    object.name = std::filesystem::path(name_or_path).stem().string();
  }
  if (!std::filesystem::exists(object.mesh_path)) {
    throw std::runtime_error("matching model '" + name_or_path + "': no such file " +
                             object.mesh_path +
                             " (built-in names: ken, cube, cylinder; else a PLY/STL/OBJ path)");
  }
  object.mesh = geometry::load_mesh(object.mesh_path);
  return object;
}

}  // namespace avs::matching
