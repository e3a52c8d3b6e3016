// Trajectories: waypoint interpolation, the manipulator motion of section 7.2.1, the lateral
// swing of section 7.1, and the ground truth a scene reports.
#include <cmath>
#include <memory>
#include <numbers>

#include <gtest/gtest.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/scene.hpp"
#include "avs/sim/trajectory.hpp"

namespace avs::sim {
namespace {

constexpr double kPi = std::numbers::pi;

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(Waypoints, InterpolatePositionLinearlyAndOrientationBySlerp) {
  const Eigen::Quaterniond q1(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  WaypointTrajectory trajectory(
      {{1.0, {0, 0, 0}, Eigen::Quaterniond::Identity()}, {3.0, {2, -4, 0}, q1}});
  const Eigen::Isometry3d mid = trajectory.T_world_object(2.0);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(1, -2, 0)));
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), kPi / 4, 1e-9);
  EXPECT_TRUE(trajectory.T_world_object(0.0).translation().isZero());  // holds before
  EXPECT_TRUE(trajectory.T_world_object(9.0).translation().isApprox(Eigen::Vector3d(2, -4, 0)));
  EXPECT_NEAR(twist_at(trajectory, 2.0).v_world_mps.norm(), std::sqrt(20.0) / 2, 1e-6);
}

TEST(Waypoints, EasedSegmentsStopAtWaypointsAndLoop) {
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  WaypointTrajectory eased({{0.0, Eigen::Vector3d(0, 0, 0), q},
                            {1.0, Eigen::Vector3d(1, 0, 0), q},
                            {2.0, Eigen::Vector3d(0, 0, 0), q}},
                           true, true);
  EXPECT_LT(twist_at(eased, 1.0, 1e-5).v_world_mps.norm(), 1e-3);
  EXPECT_NEAR(twist_at(eased, 0.5).v_world_mps.x(), 1.875, 1e-3);  // min-jerk peak 15/8
  EXPECT_TRUE(
      eased.T_world_object(2.5).translation().isApprox(eased.T_world_object(0.5).translation()));
}

TEST(Waypoints, RejectsBadTimes) {
  EXPECT_THROW(WaypointTrajectory({}), std::invalid_argument);
  const Waypoint w{1.0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};
  EXPECT_THROW(WaypointTrajectory({w, w}), std::invalid_argument);
}

TEST(Manipulator, FollowsThePapersRotationsWithinTwoSecondsAtAboutOneMetrePerSecond) {
  ManipulatorMotionConfig config;
  ManipulatorTrajectory trajectory(config);
  const Eigen::Isometry3d start = config.T_world_object_start;
  const double t0 = config.start_time_s, t_end = t0 + config.duration_s;
  EXPECT_TRUE(trajectory.T_world_object(t0 - 0.1).isApprox(start));
  // Final orientation: Rz(-pi/4) Ry(pi/4) Rz(pi/2) applied in world axes.
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(-kPi / 4, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()) *
                                   start.linear();
  EXPECT_LT(angle_between(trajectory.T_world_object(t_end).linear(), expected), 1e-9);
  EXPECT_TRUE(trajectory.T_world_object(t_end + 1).isApprox(trajectory.T_world_object(t_end)));
  // After the first segment (pi/2 of pi in total -> half the duration): a quarter turn about Z.
  const Eigen::Matrix3d after_first =
      Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()) * start.linear();
  EXPECT_LT(angle_between(trajectory.T_world_object(t0 + 1.0).linear(), after_first), 1e-9);
  // Peak speed of the ken origin about 1 m/s (section 7.2.1).
  double peak = 0;
  for (double t = t0; t <= t_end; t += 0.005)
    peak = std::max(peak, twist_at(trajectory, t).v_world_mps.norm());
  EXPECT_NEAR(peak, 1.0, 0.1);
}

TEST(LateralSwing, PeakSpeedAndAmplitudeAsConfigured) {
  LateralSwingConfig config;
  config.amplitude_m = 0.2;
  config.peak_speed_mps = 0.8;
  LateralSwingTrajectory trajectory(config);
  double peak = 0, extent = 0;
  for (double t = 0; t < 3; t += 0.002) {
    peak = std::max(peak, twist_at(trajectory, t).v_world_mps.norm());
    const Eigen::Vector3d d =
        trajectory.T_world_object(t).translation() - config.T_world_object_centre.translation();
    extent = std::max(extent, d.norm());
    EXPECT_NEAR(d.x(), 0, 1e-12);  // only along world Y
  }
  EXPECT_NEAR(peak, 0.8, 0.01);
  EXPECT_NEAR(extent, 0.2, 1e-3);
}

TEST(GroundTruth, CameraFramePoseIsWorldPoseSeenFromTheHead) {
  Scene scene;
  SceneObject ken;
  ken.name = "ken";
  ken.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("ken"));
  ken.trajectory = std::make_shared<ManipulatorTrajectory>(ManipulatorMotionConfig{});
  scene.objects.push_back(ken);
  HeadConfig head;
  const HeadState state{0.2, -0.1, 0, 0};
  const GroundTruth truth = ground_truth(scene, head, 1.2, state);
  ASSERT_EQ(truth.objects.size(), 1u);
  const ObjectTruth& o = truth.objects[0];
  EXPECT_TRUE(o.T_world_object.isApprox(ken.trajectory->T_world_object(1.2)));
  EXPECT_TRUE((truth.T_world_camera * o.T_camera_object).isApprox(o.T_world_object, 1e-12));
  EXPECT_TRUE(truth.T_world_camera.isApprox(T_world_camera(head, 0.2, -0.1)));
  EXPECT_GT(o.twist_world.v_world_mps.norm(), 0.1);  // moving at t = 1.2 s
}

TEST(Scene, BackgroundPlaneFacesTheHead) {
  const SceneObject plane = make_background_plane(2.0);
  const Eigen::Isometry3d T = plane.trajectory->T_world_object(0);
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(2.0, 0, 0)));
}

}  // namespace
}  // namespace avs::sim
