// matching: model matching of the paper's section 6 as a component. Per depth image
// (/depth/image, 32FC1 metres, NaN invalid, stamped with the newest camera frame used): target
// mask by the depth window, S-PCD (Eq. 27, voxels, outliers), Tracker (LRF initial alignment,
// ICP of Eqs. 21-26, loss and re-initialisation) -> /object/pose (camera frame),
// /object/pose_world (through the head's joint angles interpolated at the image's stamp),
// lag-compensated by the data age of /depth/info when it arrives with the image's stamp,
// /object/match, /timing and, optionally, /object/scene_points.
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <utility>

#include <boost/circular_buffer.hpp>

#include "avs/geometry/frames.hpp"
#include "avs/geometry/head_kinematics.hpp"
#include "avs/matching/joint_history.hpp"
#include "avs/matching/pipeline.hpp"
#include "avs/msg/camera_info.hpp"
#include "avs/msg/camera_input.hpp"
#include "avs/msg/convert.hpp"
#include "avs/msg/depth_image.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::matching {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class MatchingComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    runtime::QosProfile keep_last_100;
    keep_last_100.depth = 100;
    // The joint states are a history that each depth map's stamp is looked up in
    // (JointHistory keeps 0.2 s): when a depth callback runs long on the wall clock, the
    // port keeps 0.2 s of the head's 1 kHz states instead of skipping all but the newest 10,
    // which left a hole around the stamps of the depth maps still queued.
    runtime::QosProfile joint_history;
    joint_history.depth = 200;
    runtime::QosProfile best_effort_2;
    best_effort_2.depth = 2;
    best_effort_2.reliability = runtime::Reliability::best_effort;
    return {
        .type = "matching",
        .description =
            "model matching (paper section 6): /depth/image + /depth/camera_info + "
            "/head/joint_states -> /object/pose (camera), /object/pose_world, /object/match, "
            "/timing",
        .parameters = params().specs_with(
            {ParamSpec::string("model", "ken",
                               "ken | cube | cylinder (shipped models/*.ply) or a mesh path "
                               "(PLY, STL, OBJ; metres)"),
             ParamSpec::string("models_dir", "",
                               "folder of the built-in models (empty: $AVS_SOURCE_DIR/models, "
                               "else the source tree's)"),
             ParamSpec::integer("model_points", 0, 0, 100000, "",
                                "M-PCD size; 0 = the paper's (302 ken, 488 cube, 248 cylinder, "
                                "300 for a mesh)"),
             ParamSpec::integer("scene_points", 0, 0, 100000, "",
                                "i_number of Eq. 27; 0 = the paper's (250 ken, 350 cube, 300 "
                                "cylinder, 250 for a mesh)"),
             ParamSpec::real("scene_voxel_m", 0.0, 0.0, 1.0, "m",
                             "S-PCD voxel side r; 0 = the M-PCD's voxel side"),
             ParamSpec::string("icp_metric", "auto",
                               "per-frame ICP metric; auto = point_to_point for the cylinder "
                               "(point-to-plane slides along its axis), else point_to_plane",
                               {"auto", "point_to_plane", "point_to_point"}),
             ParamSpec::boolean("use_depth_info", true,
                                "with lag_compensation_s > 0: extrapolate by the data age of "
                                "/depth/info (same stamp as the image) instead of the fixed "
                                "lag_compensation_s, and keep the velocity history at the "
                                "data's time"),
             ParamSpec::string("joint_names", "pan,tilt",
                               "names of q1 and q2 in /head/joint_states"),
             ParamSpec::real("joint_max_extrapolation_s", 0.02, 0.0, 10.0, "s",
                             "joint states older than this at the image's stamp: no world pose"),
             ParamSpec::boolean("publish_scene_points", false,
                                "publish the S-PCD on /object/scene_points (camera frame)"),
             ParamSpec::boolean("publish_model_points", false,
                                "publish the M-PCD at each pose on /object/model_points (camera "
                                "frame, stamped like the pose): the model over the scene in a "
                                "viewer, like Fig. 14"),
             ParamSpec::string("report_dir", "",
                               "tests: write <name>.csv (one row per image) on deactivate")}),
        .publishes = {runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose"),
                      runtime::port<msgs::geometry_msgs::PoseStamped>("pose_world",
                                                                      "/object/pose_world"),
                      runtime::port<msgs::avs_msgs::MatchResult>("match", "/object/match"),
                      runtime::port<msgs::avs_msgs::StageTiming>("timing", "/timing",
                                                                 keep_last_100),
                      runtime::port<msgs::sensor_msgs::PointCloud2>(
                          "scene_points", "/object/scene_points", best_effort_2),
                      runtime::port<msgs::sensor_msgs::PointCloud2>(
                          "model_points", "/object/model_points", best_effort_2)},
        .subscribes = {runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image",
                                                               keep_last_4),
                       runtime::port<msgs::sensor_msgs::JointState>(
                           "joint_states", "/head/joint_states", joint_history),
                       runtime::port<msgs::avs_msgs::DepthInfo>("depth_info", "/depth/info",
                                                                keep_last_4),
                       runtime::port<msgs::sensor_msgs::CameraInfo>(
                           "camera_info", "/depth/camera_info", msg::camera_info_qos())},
        .default_mismatches = [] { return params().default_mismatches(); }};
  }

  /// The cores' configurations behind the bound parameters (their defaults are the
  /// parameters').
  struct CoreConfig {
    PipelineConfig pipeline;
    geometry::HeadConfig head;
  };

  static const runtime::ConfigParams<CoreConfig>& params() {
    static const auto p =
        runtime::ConfigParams<CoreConfig>()
            .integer("outlier_neighbours", AVS_FIELD(pipeline.scene.outlier_neighbours), 0, 1000,
                     "", "neighbours averaged by the outlier test")
            .real("outlier_distance_m", AVS_FIELD(pipeline.scene.outlier_mean_distance_m), 0.0,
                  10.0, "m", "drop S-PCD points whose mean neighbour distance is larger")
            .vector("icp_iterations", AVS_FIELD(pipeline.tracker.icp.iterations), "",
                    "[n1, n2, n3] per frame on 1/4, 1/2, all scene points", 0.0, 1000.0)
            .choice("icp_model", AVS_FIELD(pipeline.tracker.dense_icp_model),
                    std::vector<std::pair<std::string, bool>>{{"mpcd", false}, {"dense", true}},
                    "per-frame ICP model: mpcd = the M-PCD (model_points), dense = the 4000 "
                    "dense surface samples with mesh normals (less bias)")
            .real("icp_max_distance_m",
                  AVS_FIELD(pipeline.tracker.icp.max_correspondence_distance_m), 1e-4, 1.0, "m",
                  "per-frame ICP: scene points farther than this from their closest model point "
                  "are not used")
            .real("icp_trim_factor", AVS_FIELD(pipeline.tracker.icp.trim_factor), 0.0, 100.0, "",
                  "per-frame ICP: leave out pairs farther apart than this times the median pair "
                  "distance (clutter beside the target; 0 = off, docs/matching.md)")
            .real("initial_trim_factor", AVS_FIELD(pipeline.tracker.initial.trim_factor), 0.0,
                  100.0, "", "initial alignment: the same trimming in its refining ICP (0 = off)")
            .real("initial_score_trim_fraction",
                  AVS_FIELD(pipeline.tracker.initial.score_trim_fraction), 0.05, 1.0, "",
                  "initial alignment: score a pose by the mean distance of this share of the "
                  "scene points closest to the model (1 = all)")
            .real("initial_score_truncation_m",
                  AVS_FIELD(pipeline.tracker.initial.score_truncation_m), 1e-4, 1.0, "m",
                  "initial alignment: hypothesis distances are clamped to this, and its "
                  "refining ICP pairs no farther")
            .real("max_rmse_m", AVS_FIELD(pipeline.tracker.max_rmse_m), 0.0, 1.0, "m",
                  "a frame fails above this ICP RMSE (0 = model's mean spacing)")
            .live()
            .real("min_inlier_ratio", AVS_FIELD(pipeline.tracker.min_inlier_ratio), 0.0, 1.0, "",
                  "a frame fails below this inlier ratio")
            .live()
            .integer("failures_before_loss", AVS_FIELD(pipeline.tracker.failures_before_loss), 1,
                     100000, "", "consecutive failed frames that declare the target lost")
            .live()
            .integer("min_scene_points", AVS_FIELD(pipeline.tracker.min_scene_points), 3, 100000,
                     "", "fewer S-PCD points: no match (counts as a failure)")
            .live()
            .real("reacquire_within_s", AVS_FIELD(pipeline.tracker.reacquire_within_s), 0.0, 10.0,
                  "s",
                  "a lost target whose last valid pose is at most this old is first found again "
                  "by ICP from that pose (held to the initial inlier ratio), before an initial "
                  "alignment (0: off, every loss re-initialises)")
            .live()
            .integer("max_border_pixels", AVS_FIELD(pipeline.max_border_pixels), -1, 100000, "px",
                     "target-window pixels on the image border above which the target is cut "
                     "off: no pose, re-initialise when whole (-1: off)")
            .live()
            .boolean("constant_velocity", AVS_FIELD(pipeline.tracker.constant_velocity),
                     "ICP starts from the constant-velocity prediction")
            .live()
            .real("lag_compensation_s", AVS_FIELD(pipeline.lag_compensation_s), 0.0, 0.1, "s",
                  "extrapolate the published pose by this at the tracked velocity "
                  "(docs/matching.md: measured lag and why the default)")
            .live()
            .real("velocity_window_s", AVS_FIELD(pipeline.velocity_window_s), 1e-4, 1.0, "s",
                  "span of tracked poses the velocity is estimated over")
            .live()
            .real("depth_min_m", AVS_FIELD(pipeline.depth_min_m), 0.0, 100.0, "m",
                  "target mask: nearest depth")
            .live()
            .real("depth_max_m", AVS_FIELD(pipeline.depth_max_m), 0.0, 100.0, "m",
                  "target mask: farthest depth")
            .live()
            .vector("head_p_world_pan_m", AVS_FIELD(head.p_world_pan_m), "m",
                    "pan axis foot point in the world (geometry::HeadConfig)")
            .vector("head_p_pan_tilt_m", AVS_FIELD(head.p_pan_tilt_m), "m",
                    "tilt axis point in the pan-rotated frame")
            .vector("head_p_tilt_camera_m", AVS_FIELD(head.p_tilt_camera_m), "m",
                    "camera centre in the tilt-rotated frame (x = Eq. 15's a)");
    return p;
  }

  explicit MatchingComponent(ComponentContext& ctx)
      : Component(ctx),
        pose_(ctx.publisher<msgs::geometry_msgs::PoseStamped>("pose")),
        pose_world_(ctx.publisher<msgs::geometry_msgs::PoseStamped>("pose_world")),
        match_(ctx.publisher<msgs::avs_msgs::MatchResult>("match")),
        timing_(ctx.publisher<msgs::avs_msgs::StageTiming>("timing")),
        scene_points_(ctx.publisher<msgs::sensor_msgs::PointCloud2>("scene_points")),
        publish_scene_points_(ctx.param<bool>("publish_scene_points")),
        model_points_(ctx.publisher<msgs::sensor_msgs::PointCloud2>("model_points")),
        publish_model_points_(ctx.param<bool>("publish_model_points")),
        report_dir_(ctx.param<std::string>("report_dir")),
        max_extrapolation_s_(ctx.param<double>("joint_max_extrapolation_s")),
        use_depth_info_(ctx.param<bool>("use_depth_info")) {
    const ObjectModel object =
        load_object_model(ctx.param<std::string>("model"), ctx.param<std::string>("models_dir"));
    warn_if_implausible(object);
    ModelCloudConfig model_config;
    const auto model_points = ctx.param<std::int64_t>("model_points");
    model_config.target_points =
        model_points > 0 ? static_cast<std::size_t>(model_points) : object.model_points;
    const CoreConfig core = params().make(ctx.parameters());
    PipelineConfig config = core.pipeline;
    const auto scene_points = ctx.param<std::int64_t>("scene_points");
    config.scene.target_points =
        scene_points > 0 ? static_cast<std::size_t>(scene_points) : object.scene_points;
    config.scene.voxel_size_m = static_cast<float>(ctx.param<double>("scene_voxel_m"));
    for (const double n : ctx.param<std::vector<double>>("icp_iterations")) {
      if (n != std::floor(n)) {
        throw std::invalid_argument("parameter 'icp_iterations': expected integers, got " +
                                    std::to_string(n));
      }
    }
    const std::string metric = ctx.param<std::string>("icp_metric");
    config.tracker.icp.metric = metric == "auto"             ? object.metric
                                : metric == "point_to_point" ? IcpMetric::point_to_point
                                                             : IcpMetric::point_to_plane;
    pipeline_.emplace(make_model_cloud(object.mesh, model_config), config);
    log().info("model '", object.name, "' from ", object.mesh_path, ": ",
               pipeline_->model().points_m.size(), " M-PCD points, voxel ",
               1e3 * pipeline_->model().voxel_size_m, " mm");

    head_ = core.head;
    const auto names =
        msg::parse_name_list(ctx.param<std::string>("joint_names"), 2, "joint_names");
    joint_names_ = {names[0], names[1]};

    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { on_joints(*m); });
    ctx.subscribe<msgs::avs_msgs::DepthInfo>(
        "depth_info", [this](runtime::SamplePtr<msgs::avs_msgs::DepthInfo> m) { on_info(*m); });
    ctx.subscribe<msgs::sensor_msgs::CameraInfo>(
        "camera_info",
        [this](runtime::SamplePtr<msgs::sensor_msgs::CameraInfo> m) { on_camera_info(*m); });
    ctx.subscribe<msgs::sensor_msgs::Image>(
        "depth", [this](runtime::SamplePtr<msgs::sensor_msgs::Image> m) { on_depth(*m); });
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {rejected_.diagnostic()};
  }

  /// The live parameters (depth window, the tracker's per-frame checks, lag compensation)
  /// take effect from the next depth image; the tracking state is kept. An empty window is
  /// refused (the parameter service answers with the reason, nothing changes).
  void on_parameters_changed(const runtime::ParameterValues& values,
                             const std::vector<std::string>& /*changed*/) override {
    pipeline_->retune(params().make(values).pipeline);
  }

  void on_deactivate() override {
    log().info(images_, " depth images (", aged_images_, " with their /depth/info age), ", poses_,
               " poses, ", world_poses_, " world poses, ", initialisations_,
               " initial alignments, ", reacquisitions_, " re-acquisitions, state ",
               to_string(pipeline_->tracker().state()));
    if (report_dir_.empty()) return;
    const std::string file = report_dir_ + "/" + context().name() + ".csv";
    std::ofstream out(file);
    out << "t_s,state,pose_valid,x_m,y_m,z_m,qx,qy,qz,qw,world,wx_m,wy_m,wz_m,rmse_m,inliers,"
           "scene_points,processing_ms\n"
        << csv_;
    if (!out) log().error("cannot write ", file);
  }

 private:
  /// A model whose size is far from the objects a 0.3-1.5 m depth window can see is most
  /// likely in the wrong unit (millimetres for metres): said at start-up, since matching it
  /// would fail without an error (issue 20 section 2). Non-finite vertices are refused.
  void warn_if_implausible(const ObjectModel& object) {
    if (object.mesh.vertices.empty()) return;
    Eigen::Vector3f low = object.mesh.vertices.front();
    Eigen::Vector3f high = low;
    for (const auto& v : object.mesh.vertices) {
      if (!v.allFinite()) {
        throw std::invalid_argument("model '" + object.name + "' (" + object.mesh_path +
                                    ") has a vertex that is not finite");
      }
      low = low.cwiseMin(v);
      high = high.cwiseMax(v);
    }
    const double size_m = static_cast<double>((high - low).norm());
    if (size_m < 0.005 || size_m > 5.0) {
      log().warn("model '", object.name, "' (", object.mesh_path, ") is ", size_m,
                 " m across: implausible for a 0.3-1.5 m depth window; is the mesh in metres?");
    }
  }

  void on_joints(const msgs::sensor_msgs::JointState& m) {
    std::optional<double> q[2];
    for (std::size_t axis = 0; axis < 2; ++axis) {
      if (const auto joint = msg::find_joint(m, joint_names_[axis])) q[axis] = joint->position;
      if (q[axis] && !std::isfinite(*q[axis])) {
        rejected_.reject("joint state '" + joint_names_[axis] + "' position not finite");
        return;
      }
    }
    if (!q[0] || !q[1]) {
      if (!warned_joint_names_) {
        log().warn("/head/joint_states without both joints '", joint_names_[0], "' and '",
                   joint_names_[1], "': ignored");
      }
      warned_joint_names_ = true;
      return;
    }
    joints_.add({runtime::from_ros_time(m.header.stamp).seconds(), *q[0], *q[1]});
  }

  void on_info(const msgs::avs_msgs::DepthInfo& m) {
    if (!use_depth_info_ || !std::isfinite(m.data_age_s) || m.data_age_s < 0.0) return;
    // When full, the oldest is overwritten.
    ages_.push_back({runtime::from_ros_time(m.header.stamp).seconds(), m.data_age_s});
  }

  /// The data age /depth/info gave for this stamp, if it came.
  std::optional<double> age_at(double stamp_s) const {
    for (auto it = ages_.rbegin(); it != ages_.rend(); ++it) {
      if (it->first == stamp_s) return it->second;
    }
    return std::nullopt;
  }

  void on_camera_info(const msgs::sensor_msgs::CameraInfo& m) {
    if (camera_.update(m)) pipeline_->set_camera(*camera_.model());
  }

  void on_depth(const msgs::sensor_msgs::Image& image) {
    std::string why;
    const auto layout = msg::depth_view(image, &why);
    if (!layout) {
      rejected_.reject(why);
      return;
    }
    if (!camera_.accepts_image(layout->width_px, layout->height_px)) return;
    ++images_;
    const double stamp_s = runtime::from_ros_time(image.header.stamp).seconds();
    const DepthView& depth = *layout;
    const std::optional<double> age = age_at(stamp_s);
    if (age) ++aged_images_;
    const PipelineOutput out =
        age ? pipeline_->process(depth, stamp_s, *age) : pipeline_->process(depth, stamp_s);
    if (out.track.initialised_this_frame) ++initialisations_;
    if (out.track.reacquired_this_frame) ++reacquisitions_;

    std::optional<Eigen::Isometry3d> T_world_model;
    if (out.has_pose) {
      ++poses_;
      const Eigen::Isometry3d T_camera_model = out.T_camera_model.cast<double>();
      publish_pose(pose_, image.header.stamp, geometry::frame::kCameraOptical, T_camera_model);
      if (publish_model_points_) publish_model(image, out.T_camera_model);
      if (const auto q = joints_.at(stamp_s, max_extrapolation_s_)) {
        T_world_model = geometry::T_world_camera(head_, q->pan_rad, q->tilt_rad) * T_camera_model;
        publish_pose(pose_world_, image.header.stamp, geometry::frame::kWorld, *T_world_model);
        ++world_poses_;
      } else if (!warned_no_joints_) {
        log().warn("no /head/joint_states around t = ", stamp_s,
                   " s: /object/pose_world not published");
        warned_no_joints_ = true;
      }
    }
    publish_match(image, out);
    publish_timing(image, out.processing_ms);
    if (publish_scene_points_) publish_cloud(image);
    if (!report_dir_.empty()) report(stamp_s, out, T_world_model);
  }

  void publish_pose(const runtime::Publisher<msgs::geometry_msgs::PoseStamped>& publisher,
                    const decltype(msgs::sensor_msgs::Image::header.stamp)& stamp,
                    std::string_view frame, const Eigen::Isometry3d& T) {
    auto msg = publisher.loan();  // every field set below
    msg->header.stamp = stamp;
    runtime::set_string(msg->header.frame_id, frame);
    msg::to_pose(T, msg->pose);
    publisher.publish(std::move(msg));
  }

  static std::uint8_t state_of(const PipelineOutput& out) {
    // The update on which the initial alignment ran reports INITIALISING (its processing time
    // is the alignment's, Sec. 6.1), whether or not tracking starts from it.
    if (out.track.initialised_this_frame && out.track.state != TrackingState::lost) {
      return avs_msgs_msg_dds__MatchResult_Constants_STATE_INITIALISING;
    }
    switch (out.track.state) {
      case TrackingState::tracking:
        return avs_msgs_msg_dds__MatchResult_Constants_STATE_TRACKING;
      case TrackingState::lost:
        return avs_msgs_msg_dds__MatchResult_Constants_STATE_LOST;
      case TrackingState::waiting:
        return out.track.initialised_this_frame
                   ? avs_msgs_msg_dds__MatchResult_Constants_STATE_INITIALISING
                   : avs_msgs_msg_dds__MatchResult_Constants_STATE_IDLE;
    }
    return avs_msgs_msg_dds__MatchResult_Constants_STATE_IDLE;
  }

  void publish_match(const msgs::sensor_msgs::Image& image, const PipelineOutput& out) {
    auto msg = match_.loan();  // every field set below
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->header.frame_id, geometry::frame::kCameraOptical);
    msg::to_pose(out.T_camera_model.cast<double>(), msg->pose);
    msg->rmse_m = out.track.icp.rmse_m;
    msg->inliers = static_cast<std::uint32_t>(out.track.icp.inliers);
    msg->scene_points = static_cast<std::uint32_t>(out.scene_points);
    msg->iterations = static_cast<std::uint32_t>(out.track.icp.iterations);
    msg->state = state_of(out);
    msg->processing_time_ms = out.processing_ms;
    match_.publish(std::move(msg));
  }

  void publish_timing(const msgs::sensor_msgs::Image& image, double processing_ms) {
    auto msg = timing_.loan();  // every field set below
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->header.frame_id, runtime::get_string(image.header.frame_id));
    runtime::set_string(msg->stage, "matching");
    msg->processing_ms = processing_ms;
    timing_.publish(std::move(msg));
  }

  void publish_cloud(const msgs::sensor_msgs::Image& image) {
    const Points& points = pipeline_->scene_points();
    auto msg = scene_points_.loan();  // every field set below (write_xyz_cloud: all but the header)
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->header.frame_id, geometry::frame::kCameraOptical);
    msg::write_xyz_cloud(points, *msg);
    scene_points_.publish(std::move(msg));
  }

  /// The M-PCD moved to the published pose: p_camera = T_camera_model p_model.
  void publish_model(const msgs::sensor_msgs::Image& image,
                     const Eigen::Isometry3f& T_camera_model) {
    const Points& model = pipeline_->model().points_m;
    model_in_camera_.resize(model.size());
    for (std::size_t i = 0; i < model.size(); ++i) model_in_camera_[i] = T_camera_model * model[i];
    auto msg = model_points_.loan();  // every field set below (write_xyz_cloud: all but the header)
    msg->header.stamp = image.header.stamp;
    runtime::set_string(msg->header.frame_id, geometry::frame::kCameraOptical);
    msg::write_xyz_cloud(model_in_camera_, *msg);
    model_points_.publish(std::move(msg));
  }

  void report(double stamp_s, const PipelineOutput& out,
              const std::optional<Eigen::Isometry3d>& T_world_model) {
    const Eigen::Vector3f p = out.T_camera_model.translation();
    const Eigen::Quaternionf q(out.T_camera_model.linear());
    const Eigen::Vector3d w =
        T_world_model ? Eigen::Vector3d(T_world_model->translation()) : Eigen::Vector3d::Zero();
    char line[512];
    std::snprintf(line, sizeof line,
                  "%.6f,%d,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%d,%.6f,%.6f,%.6f,%.6f,%zu,%zu,"
                  "%.3f\n",
                  stamp_s, static_cast<int>(state_of(out)), out.has_pose ? 1 : 0, p.x(), p.y(),
                  p.z(), q.x(), q.y(), q.z(), q.w(), T_world_model ? 1 : 0, w.x(), w.y(), w.z(),
                  out.track.icp.rmse_m, out.track.icp.inliers, out.scene_points, out.processing_ms);
    csv_ += line;
  }

  runtime::Publisher<msgs::geometry_msgs::PoseStamped> pose_;
  runtime::Publisher<msgs::geometry_msgs::PoseStamped> pose_world_;
  runtime::Publisher<msgs::avs_msgs::MatchResult> match_;
  runtime::Publisher<msgs::avs_msgs::StageTiming> timing_;
  runtime::Publisher<msgs::sensor_msgs::PointCloud2> scene_points_;
  std::optional<MatchingPipeline> pipeline_;
  geometry::HeadConfig head_;
  std::array<std::string, 2> joint_names_;
  JointHistory joints_;
  bool publish_scene_points_;
  runtime::Publisher<msgs::sensor_msgs::PointCloud2> model_points_;
  bool publish_model_points_;
  Points model_in_camera_;  ///< publish_model's buffer
  std::string report_dir_;
  double max_extrapolation_s_;
  bool use_depth_info_;
  /// (stamp, data age) of the newest 16 /depth/info; fixed storage, no allocation per message.
  boost::circular_buffer<std::pair<double, double>> ages_{16};
  runtime::SampleRejections rejected_{log(), "input"};
  msg::CameraInput camera_{log(), rejected_};  ///< from /depth/camera_info
  bool warned_no_joints_ = false;
  bool warned_joint_names_ = false;
  std::uint64_t images_ = 0, aged_images_ = 0, poses_ = 0, world_poses_ = 0, initialisations_ = 0;
  std::uint64_t reacquisitions_ = 0;
  std::string csv_;
};

AVS_REGISTER_COMPONENT(MatchingComponent);

}  // namespace avs::matching
