// Depth image -> object pose, the whole per-frame path of the `matching` component without DDS:
// target mask by a depth window (as the tracking component's phi_l < h < phi_h, Eq. 8), S-PCD
// (section 6.3, Eq. 27), Tracker (initial alignment, ICP, loss), and an optional extrapolation
// of the pose by the tracker's velocity to the image's stamp (the rolling depth map mixes the
// last 2n frames, so the matched pose lags the newest frame; docs/matching.md measures it).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "avs/geometry/mesh.hpp"
#include "avs/matching/border_regions.hpp"
#include "avs/matching/model_cloud.hpp"
#include "avs/matching/pose_error.hpp"
#include "avs/matching/scene_cloud.hpp"
#include "avs/matching/tracker.hpp"

namespace avs::matching {

struct PipelineConfig {
  /// The depth camera: the matching component sets it from /depth/camera_info (offline users
  /// from the calibration file); process() rejects an unset one.
  geometry::CameraModel camera;
  /// Target mask: pixels with depth_min_m <= z <= depth_max_m (SceneCloudConfig's min/max depth
  /// are overwritten by these).
  float depth_min_m = 0.3F;
  float depth_max_m = 1.5F;
  SceneCloudConfig scene;
  TrackerConfig tracker;
  /// The published pose is the matched pose moved forward by this much at the tracker's velocity
  /// (0 = off). The matched pose describes the object some milliseconds before the newest frame.
  double lag_compensation_s = 0.0;
  /// The velocity is the mean motion over the valid tracked poses of the last this many
  /// seconds (one frame-to-frame difference is too noisy to extrapolate by).
  double velocity_window_s = 0.01;
  /// Also extrapolate the orientation (the angular velocity of a few tracked poses is noisy).
  bool lag_compensate_rotation = false;
  /// A target cut by the image border (more than this many target-window pixels on the
  /// outermost rows/columns) is only partly seen: ICP and the initial alignment would fit the
  /// visible part anywhere, so the frame gives no pose and the tracker starts over when the
  /// target is whole again. Negative: off.
  int max_border_pixels = 20;
  /// Clutter cut by the border (issue 19: a board crossing the view in front of the target):
  /// when more than max_border_pixels target-window pixels are on the border, the surfaces
  /// connected to the border through depth steps of at most border_region_step_m are left out
  /// (BorderRegions), and if at least this many target-window pixels remain, the frame is
  /// matched on them instead of being given up. 0: every such frame is given up.
  int min_pixels_beside_border_clutter = 200;
  float border_region_step_m = 0.02F;
  /// ... and only when the border-connected surfaces lie at least this far in depth from the
  /// rest (medians, BorderRegions::depth_separation_m): an occluder in front of the target. A
  /// target that is itself cut by the border (parts of it split off by depth steps) is not, and
  /// such a frame is still given up (without this, the ken swinging out of the still head's
  /// view was matched on its split-off parts: 621 flips instead of 405 in `no_tracking`).
  float border_clutter_min_separation_m = 0.1F;
};

/// Per-frame result of MatchingPipeline::process().
struct PipelineOutput {
  TrackResult track;
  /// The pose to publish: track.T_camera_model, extrapolated by lag_compensation_s while
  /// tracking with a velocity estimate.
  Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
  bool has_pose = false;         ///< tracking: T_camera_model is the object's pose
  bool lag_compensated = false;  ///< T_camera_model was extrapolated
  std::size_t valid_pixels = 0;
  std::size_t scene_points = 0;
  std::size_t border_pixels = 0;  ///< target-window pixels on the image border
  bool truncated = false;         ///< border_pixels > max_border_pixels: no pose
  /// Target-window pixels left out as clutter cut by the border (0 when none was).
  std::size_t border_clutter_pixels = 0;
  double processing_ms = 0.0;  ///< wall-clock time of process()
};

class MatchingPipeline {
 public:
  MatchingPipeline(ModelCloud model, PipelineConfig config);

  /// One depth image (metres, NaN or 0 invalid) taken at stamp_s.
  PipelineOutput process(const DepthView& depth, double stamp_s);
  /// Same for a depth image whose information is data_age_s older than stamp_s (a rolling
  /// map: decode::DecodeResult::effective_age_pairs x 2 frame periods + half a period). The
  /// velocity history is kept at stamp_s - data_age_s and, when lag_compensation_s > 0, the
  /// published pose is extrapolated by data_age_s (instead of the constant lag_compensation_s)
  /// to stamp_s.
  PipelineOutput process(const DepthView& depth, double stamp_s, double data_age_s);

  void reset() { tracker_.reset(); }
  /// The live settings of `config`, the tracking state kept (the matching component's live
  /// parameters): the depth window, lag compensation, velocity window, border limit and the
  /// tracker's per-frame checks (Tracker::retune). Throws std::invalid_argument, changing
  /// nothing, when the window is empty or the lag settings are out of range.
  void retune(const PipelineConfig& config);
  /// The camera model in force (from /depth/camera_info); the tracker's state is kept.
  void set_camera(const geometry::CameraModel& camera) { config_.camera = camera; }
  [[nodiscard]] const Points& scene_points() const { return *scene_; }
  [[nodiscard]] const ModelCloud& model() const { return model_; }
  [[nodiscard]] const PipelineConfig& config() const { return config_; }
  [[nodiscard]] const Tracker& tracker() const { return tracker_; }

 private:
  /// Target-window pixels on the outermost rows and columns.
  [[nodiscard]] std::size_t border_pixels(const DepthView& depth) const;
  ModelCloud model_;
  PipelineConfig config_;
  SceneCloudBuilder builder_;
  BorderRegions border_regions_;
  Tracker tracker_;
  const Points* scene_;
  Points empty_;
  struct Stamped {
    double stamp_s;
    Eigen::Isometry3f T_camera_model;
  };
  /// Oldest first. A vector (the front erased in place: a window of a few dozen poses), not a
  /// deque, which mallocs and frees a block every few poses (no allocation per frame, issue 16).
  std::vector<Stamped> history_;
};

/// A matching object: mesh, M-PCD size, i_number and symmetry (for error statistics only).
struct ObjectModel {
  std::string name;
  std::string mesh_path;
  geometry::Mesh mesh;
  std::size_t model_points = 0;
  std::size_t scene_points = 0;
  Symmetry symmetry = Symmetry::none;
  /// Per-frame ICP metric that suits the object: point-to-point for a cylinder (point-to-plane
  /// lets it slide along its axis when the caps are barely seen), point-to-plane otherwise.
  IcpMetric metric = IcpMetric::point_to_plane;
};

/// "ken", "cube", "cylinder": the shipped models/<name>.ply with the paper's sizes (section 7.2:
/// 302/250 ken, 488/350 cube, 248/300 cylinder); anything else is a mesh path (PLY, STL, OBJ)
/// with 300 model and 250 scene points and no symmetry. models_dir empty: $AVS_SOURCE_DIR/models,
/// else the source tree's models/. Throws std::runtime_error naming the file when it cannot load.
[[nodiscard]] ObjectModel load_object_model(const std::string& name_or_path,
                                            const std::string& models_dir = "");

/// (The folder of the built-in models: geometry::default_models_dir().)

}  // namespace avs::matching
