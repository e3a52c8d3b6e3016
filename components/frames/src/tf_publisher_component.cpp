// tf_publisher: the rig's frames for viewers (Foxglove, RViz) on /tf and /tf_static
// (tf2_msgs/msg/TFMessage), with the names of geometry/frames.hpp:
//   /tf_static (latched, at activation): tilt_link -> camera_optical_frame (the head's camera
//     mount) and camera_optical_frame -> projector_optical_frame (the sensor calibration);
//   /tf: world -> pan_link and pan_link -> tilt_link at each /head/joint_states stamp (the head
//     kinematics of geometry/head_kinematics.hpp), and camera_optical_frame -> object at each
//     /object/pose stamp (matching's pose, whose frame must be camera_optical_frame).
#include <Eigen/Geometry>

#include "avs/decode/calibration_yaml.hpp"
#include "avs/decode/sensor_geometry.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/geometry/head_kinematics.hpp"
#include "avs/msg/convert.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/config_params.hpp"
#include "avs/runtime/rejections.hpp"

namespace avs::frames {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;
namespace frame = geometry::frame;

namespace {

using Stamp = decltype(msgs::std_msgs::Header::stamp);

void set_transform(msgs::geometry_msgs::TransformStamped& out, const Stamp& stamp,
                   const char* parent, const char* child, const Eigen::Isometry3d& T) {
  out.header.stamp = stamp;
  runtime::set_string(out.header.frame_id, parent);
  runtime::set_string(out.child_frame_id, child);
  msgs::geometry_msgs::Pose pose{};
  msg::to_pose(T, pose);
  out.transform.translation.x = pose.position.x;
  out.transform.translation.y = pose.position.y;
  out.transform.translation.z = pose.position.z;
  out.transform.rotation = pose.orientation;
}

}  // namespace

class TfPublisher final : public runtime::Component {
 public:
  static const runtime::ConfigParams<geometry::HeadConfig>& params() {
    static const auto p = runtime::ConfigParams<geometry::HeadConfig>()
                              .vector("head_p_world_pan_m", AVS_FIELD(p_world_pan_m), "m",
                                      "pan axis foot point in the world (geometry::HeadConfig)")
                              .vector("head_p_pan_tilt_m", AVS_FIELD(p_pan_tilt_m), "m",
                                      "tilt axis point in the pan-rotated frame")
                              .vector("head_p_tilt_camera_m", AVS_FIELD(p_tilt_camera_m), "m",
                                      "camera centre in the tilt-rotated frame (x = Eq. 15's a)");
    return p;
  }

  static ComponentSpec spec() {
    return {.type = "tf_publisher",
            .description =
                "the rig's frames: /head/joint_states + /object/pose -> /tf, head "
                "mount and projector -> /tf_static (docs/view.md)",
            .parameters = params().specs_with(
                {ParamSpec::string("joint_names", "pan,tilt",
                                   "names of q1 and q2 in /head/joint_states"),
                 ParamSpec::string("calibration_file", "",
                                   "sensor geometry YAML for the projector pose (docs/decode.md); "
                                   "empty: the paper's sensor, default_sensor_geometry()")}),
            .publishes = {runtime::port<msgs::tf2_msgs::TFMessage>("tf", "/tf"),
                          runtime::port<msgs::tf2_msgs::TFMessage>(
                              "tf_static", "/tf_static",
                              *runtime::QosProfile::named("transient_local"))},
            .subscribes = {runtime::port<msgs::sensor_msgs::JointState>("joint_states",
                                                                        "/head/joint_states"),
                           runtime::port<msgs::geometry_msgs::PoseStamped>("pose", "/object/pose")},
            .default_mismatches = [] { return params().default_mismatches(); }};
  }

  explicit TfPublisher(ComponentContext& ctx)
      : Component(ctx),
        tf_(ctx.publisher<msgs::tf2_msgs::TFMessage>("tf")),
        tf_static_(ctx.publisher<msgs::tf2_msgs::TFMessage>("tf_static")),
        head_(params().make(ctx.parameters())) {
    const auto names =
        msg::parse_name_list(ctx.param<std::string>("joint_names"), 2, "joint_names");
    pan_name_ = names[0];
    tilt_name_ = names[1];
    const auto file = ctx.param<std::string>("calibration_file");
    const decode::SensorGeometry sensor =
        file.empty() ? decode::default_sensor_geometry() : decode::load_sensor_geometry_yaml(file);
    // p_projector = R_projector_camera p_camera + t: that is T_projector_camera; /tf wants the
    // child (projector) in the parent (camera).
    Eigen::Isometry3d T_projector_camera = Eigen::Isometry3d::Identity();
    T_projector_camera.linear() = sensor.R_projector_camera;
    T_projector_camera.translation() = sensor.t_projector_camera_m;
    T_camera_projector_ = T_projector_camera.inverse();
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "joint_states",
        [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) { on_joints(*m); });
    ctx.subscribe<msgs::geometry_msgs::PoseStamped>(
        "pose", [this](runtime::SamplePtr<msgs::geometry_msgs::PoseStamped> m) { on_pose(*m); });
  }

  void on_activate() override {
    auto msg = runtime::make_sample<msgs::tf2_msgs::TFMessage>();
    runtime::resize_sequence(msg->transforms, 2);
    Stamp stamp{};
    runtime::to_ros_time(context().now(), stamp);
    set_transform(msg->transforms._buffer[0], stamp, frame::kTiltLink, frame::kCameraOptical,
                  geometry::T_tilt_camera(head_));
    set_transform(msg->transforms._buffer[1], stamp, frame::kCameraOptical,
                  frame::kProjectorOptical, T_camera_projector_);
    tf_static_.publish(std::move(msg));
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {rejected_.diagnostic()};
  }

 private:
  void on_joints(const msgs::sensor_msgs::JointState& m) {
    const auto pan = msg::find_joint(m, pan_name_);
    const auto tilt = msg::find_joint(m, tilt_name_);
    if (!pan || !tilt) {
      rejected_.reject("/head/joint_states without joints '" + pan_name_ + "' and '" + tilt_name_ +
                       "'");
      return;
    }
    auto msg = runtime::make_sample<msgs::tf2_msgs::TFMessage>();
    runtime::resize_sequence(msg->transforms, 2);
    set_transform(msg->transforms._buffer[0], m.header.stamp, frame::kWorld, frame::kPanLink,
                  geometry::T_world_pan(head_, pan->position));
    set_transform(msg->transforms._buffer[1], m.header.stamp, frame::kPanLink, frame::kTiltLink,
                  geometry::T_pan_tilt(head_, tilt->position));
    tf_.publish(std::move(msg));
  }

  void on_pose(const msgs::geometry_msgs::PoseStamped& m) {
    const auto frame_id = runtime::get_string(m.header.frame_id);
    if (frame_id != frame::kCameraOptical) {
      rejected_.reject("/object/pose in frame '" + std::string(frame_id) + "', not '" +
                       frame::kCameraOptical + "'");
      return;
    }
    if (!msg::is_finite(m.pose)) {
      rejected_.reject("/object/pose with a non-finite pose");
      return;
    }
    auto msg = runtime::make_sample<msgs::tf2_msgs::TFMessage>();
    runtime::resize_sequence(msg->transforms, 1);
    set_transform(msg->transforms._buffer[0], m.header.stamp, frame::kCameraOptical, frame::kObject,
                  msg::to_isometry(m.pose));
    tf_.publish(std::move(msg));
  }

  runtime::Publisher<msgs::tf2_msgs::TFMessage> tf_;
  runtime::Publisher<msgs::tf2_msgs::TFMessage> tf_static_;
  geometry::HeadConfig head_;
  std::string pan_name_, tilt_name_;
  Eigen::Isometry3d T_camera_projector_ = Eigen::Isometry3d::Identity();
  runtime::SampleRejections rejected_{log(), "input"};
};

AVS_REGISTER_COMPONENT(TfPublisher);

}  // namespace avs::frames
