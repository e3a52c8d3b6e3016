// test_depth_target: a stand-in for sim_scene + decode in the tracking graph tests. Publishes
// 32FC1 depth images (metres along the optical axis, NaN = no surface) of one sphere swinging
// laterally in front of the head, seen through the TRUE head angles from /sim/head_state.
// Head kinematics (docs/servo.md section 1): camera at the rotation centre (a = 0), optical
// axis +z at q = 0, x right, y down; R_world_camera = Ry(q1) Rx(-q2), so positive pan turns the
// axis toward image +x and positive tilt toward image +y, as Eq. 15's Jacobian assumes. Like
// decode it publishes the camera model on /depth/camera_info: the paper's default camera.
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "avs/decode/sensor_geometry.hpp"
#include "avs/geometry/frames.hpp"
#include "avs/msg/camera_info.hpp"
#include "avs/runtime/component.hpp"

namespace avs::tracking {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class TestDepthTarget final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    runtime::QosProfile keep_last_4;
    keep_last_4.depth = 4;
    return {
        .type = "test_depth_target",
        .description =
            "tests: depth images of a sphere swinging laterally (x = A sin(v t / A)) "
            "in front of the simulated head, through the true head angles",
        .parameters =
            {ParamSpec::real("rate_hz", 500.0, 1.0, 10000.0, "Hz", "image rate"),
             ParamSpec::real("distance_m", 1.0, 0.1, 100.0, "m", "sphere centre's z"),
             ParamSpec::real("radius_m", 0.05, 0.001, 10.0, "m", "sphere radius"),
             ParamSpec::real("amplitude_m", 0.5, 0.0, 100.0, "m", "lateral swing amplitude A"),
             ParamSpec::real("peak_speed_m_s", 1.0, 0.0, 100.0, "m/s", "peak lateral speed v"),
             ParamSpec::real("height_m", 0.0, -100.0, 100.0, "m", "sphere centre's y (image down)"),
             ParamSpec::real("start_s", 0.2, 0.0, std::nullopt, "s", "swing starts")},
        .publishes = {runtime::port<msgs::sensor_msgs::Image>("depth", "/depth/image", keep_last_4),
                      runtime::port<msgs::sensor_msgs::CameraInfo>(
                          "camera_info", "/depth/camera_info", msg::camera_info_qos())},
        .subscribes = {
            runtime::port<msgs::sensor_msgs::JointState>("head_state", "/sim/head_state")}};
  }

  explicit TestDepthTarget(ComponentContext& ctx)
      : Component(ctx),
        depth_(ctx.publisher<msgs::sensor_msgs::Image>("depth")),
        camera_info_(ctx.publisher<msgs::sensor_msgs::CameraInfo>("camera_info")),
        period_(static_cast<std::int64_t>(std::llround(1e9 / ctx.param<double>("rate_hz")))),
        width_(camera_.width),
        height_(camera_.height),
        f_(camera_.fx_px),
        cx_(camera_.cx_px),
        cy_(camera_.cy_px),
        distance_(ctx.param<double>("distance_m")),
        radius_(ctx.param<double>("radius_m")),
        amplitude_(ctx.param<double>("amplitude_m")),
        speed_(ctx.param<double>("peak_speed_m_s")),
        height_m_(ctx.param<double>("height_m")),
        start_s_(ctx.param<double>("start_s")) {
    ctx.subscribe<msgs::sensor_msgs::JointState>(
        "head_state", [this](runtime::SamplePtr<msgs::sensor_msgs::JointState> m) {
          if (m->position._length >= 2) q_ = {m->position._buffer[0], m->position._buffer[1]};
        });
  }

  void on_activate() override {
    auto info = runtime::make_sample<msgs::sensor_msgs::CameraInfo>();
    msg::to_camera_info(camera_, *info);
    runtime::set_string(info->header.frame_id, geometry::frame::kCameraOptical);
    camera_info_.publish(std::move(info));
    context().create_timer(period_, [this] { render(); });
  }

 private:
  void render() {
    const runtime::Time now = context().now();
    const double t = std::max(0.0, now.seconds() - start_s_);
    const double x = amplitude_ > 0 ? amplitude_ * std::sin(speed_ / amplitude_ * t) : 0.0;
    const Eigen::Vector3d centre_world(x, height_m_, distance_);
    const Eigen::Matrix3d r_world_camera = (Eigen::AngleAxisd(q_[0], Eigen::Vector3d::UnitY()) *
                                            Eigen::AngleAxisd(-q_[1], Eigen::Vector3d::UnitX()))
                                               .toRotationMatrix();
    const Eigen::Vector3d c = r_world_camera.transpose() * centre_world;  // camera frame

    auto image = runtime::make_sample<msgs::sensor_msgs::Image>();
    runtime::to_ros_time(now, image->header.stamp);
    runtime::set_string(image->header.frame_id, geometry::frame::kCameraOptical);
    runtime::set_string(image->encoding, "32FC1");
    image->width = static_cast<std::uint32_t>(width_);
    image->height = static_cast<std::uint32_t>(height_);
    image->step = image->width * 4;
    runtime::resize_sequence(image->data, image->step * image->height);
    auto* depth = reinterpret_cast<float*>(image->data._buffer);
    std::fill(depth, depth + static_cast<std::size_t>(width_) * height_,
              std::numeric_limits<float>::quiet_NaN());
    if (c.z() > radius_) {
      // Pixels inside the sphere's projected bounding box, ray-sphere intersection each.
      const double half =
          f_ * radius_ / std::sqrt(std::max(c.z() * c.z() - radius_ * radius_, 1e-9));
      const double uc = cx_ + f_ * c.x() / c.z();
      const double vc = cy_ + f_ * c.y() / c.z();
      const double margin = 2.0 * half + 2.0;
      const int u0 = std::max(0, static_cast<int>(std::floor(uc - margin)));
      const int u1 = std::min(width_ - 1, static_cast<int>(std::ceil(uc + margin)));
      const int v0 = std::max(0, static_cast<int>(std::floor(vc - margin)));
      const int v1 = std::min(height_ - 1, static_cast<int>(std::ceil(vc + margin)));
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          const Eigen::Vector3d ray((u - cx_) / f_, (v - cy_) / f_, 1.0);  // z = 1
          const double a = ray.squaredNorm();
          const double b = ray.dot(c);
          const double disc = b * b - a * (c.squaredNorm() - radius_ * radius_);
          if (disc < 0) continue;
          const double s = (b - std::sqrt(disc)) / a;  // nearest hit; depth z = s
          if (s > 0) depth[static_cast<std::size_t>(v) * width_ + u] = static_cast<float>(s);
        }
      }
    }
    depth_.publish(std::move(image));
  }

  const geometry::CameraModel camera_ = decode::default_sensor_geometry().camera;
  runtime::Publisher<msgs::sensor_msgs::Image> depth_;
  runtime::Publisher<msgs::sensor_msgs::CameraInfo> camera_info_;
  runtime::Duration period_;
  int width_;
  int height_;
  double f_, cx_, cy_;
  double distance_, radius_, amplitude_, speed_, height_m_, start_s_;
  Eigen::Vector2d q_ = Eigen::Vector2d::Zero();
};

AVS_REGISTER_COMPONENT(TestDepthTarget);

}  // namespace avs::tracking
