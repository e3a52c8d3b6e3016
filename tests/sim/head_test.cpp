// Pan/tilt head kinematics and the renderer placing objects where the head looks.
#include <cmath>
#include <memory>
#include <numbers>

#include <gtest/gtest.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/head.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {
namespace {

TEST(Head, ZeroAnglesLookAlongWorldXWithCameraOffsetA) {
  HeadConfig head;
  head.p_tilt_camera_m = Eigen::Vector3d(0.05, 0, 0);
  const Eigen::Isometry3d T = T_world_camera(head, 0, 0);
  EXPECT_TRUE(T.linear().col(2).isApprox(Eigen::Vector3d::UnitX()));   // optical axis
  EXPECT_TRUE(T.linear().col(0).isApprox(-Eigen::Vector3d::UnitY()));  // image x to the right
  EXPECT_TRUE(T.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ()));  // image y down
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.05, 0, 0)));
}

TEST(Head, LinksOfTfComposeToTheCameraPose) {
  // /tf's world -> pan_link -> tilt_link -> camera_optical_frame (components/frames): the pan
  // link turns about the world's Z only, the tilt link about pan_link's Y only, the mount is
  // fixed, and together they are T_world_camera.
  HeadConfig head;
  head.p_world_pan_m = Eigen::Vector3d(0.1, -0.2, 0.3);
  head.p_pan_tilt_m = Eigen::Vector3d(0.01, 0.02, 0.05);
  const double pan = 0.3, tilt = -0.2;
  const Eigen::Isometry3d T_world_pan = geometry::T_world_pan(head, pan);
  const Eigen::Isometry3d T_pan_tilt = geometry::T_pan_tilt(head, tilt);
  EXPECT_TRUE((T_world_pan.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((T_pan_tilt.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(T_world_pan.translation().isApprox(head.p_world_pan_m));
  EXPECT_TRUE(T_pan_tilt.translation().isApprox(head.p_pan_tilt_m));
  const Eigen::Isometry3d composed = T_world_pan * T_pan_tilt * geometry::T_tilt_camera(head);
  EXPECT_TRUE(composed.isApprox(T_world_camera(head, pan, tilt)));
  EXPECT_TRUE(geometry::T_tilt_camera(head).translation().isApprox(head.p_tilt_camera_m));
}

TEST(Head, PositivePanTurnsRightPositiveTiltLooksDownAndTheOffsetSwingsWithThem) {
  // Servo convention (docs/servo.md section 1): positive pan turns the optical axis toward
  // image +x (world -Y at home), positive tilt toward image +y (down).
  HeadConfig head;
  head.p_tilt_camera_m = Eigen::Vector3d(0.05, 0, 0);
  const Eigen::Isometry3d pan = T_world_camera(head, std::numbers::pi / 2, 0);
  EXPECT_TRUE(pan.linear().col(2).isApprox(-Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(pan.translation().isApprox(Eigen::Vector3d(0, -0.05, 0)));
  const Eigen::Isometry3d tilt = T_world_camera(head, 0, 0.3);
  EXPECT_NEAR(tilt.linear().col(2).z(), -std::sin(0.3), 1e-12);
  EXPECT_NEAR(tilt.translation().z(), -0.05 * std::sin(0.3), 1e-12);
  // The new axis direction, seen from the home camera frame, lies toward image +x / +y.
  const Eigen::Matrix3d R_home = T_world_camera(head, 0, 0).linear();
  EXPECT_GT((R_home.transpose() * T_world_camera(head, 0.1, 0).linear().col(2)).x(), 0.09);
  EXPECT_GT((R_home.transpose() * T_world_camera(head, 0, 0.1).linear().col(2)).y(), 0.09);
}

TEST(Head, SmallPositivePanOrTiltMovesAStaticPointsImageTowardMinusXOrMinusY) {
  // Eq. 15: d m_x / d q1 = -f cos q2, d m_y / d q2 = -f (here at q2 = 0, offsets zero).
  HeadConfig head;
  head.p_tilt_camera_m.setZero();
  const Eigen::Vector3d p_world(1.0, 0.0, 0.0);
  const auto image = [&](double pan, double tilt) {
    const Eigen::Vector3d p = T_world_camera(head, pan, tilt).inverse() * p_world;
    return Eigen::Vector2d(p.x() / p.z(), p.y() / p.z());  // normalised image coordinates
  };
  const double dq = 1e-4;
  const Eigen::Vector2d d_pan = (image(dq, 0) - image(0, 0)) / dq;
  const Eigen::Vector2d d_tilt = (image(0, dq) - image(0, 0)) / dq;
  EXPECT_NEAR(d_pan.x(), -1.0, 1e-3);
  EXPECT_NEAR(d_pan.y(), 0.0, 1e-6);
  EXPECT_NEAR(d_tilt.x(), 0.0, 1e-6);
  EXPECT_NEAR(d_tilt.y(), -1.0, 1e-3);
  // At q2 = 0.5 the pan gain shrinks by cos q2 (Eq. 15's -f cos q2).
  const Eigen::Vector3d p_below(std::cos(0.5), 0.0, -std::sin(0.5));
  const auto image_below = [&](double pan) {
    const Eigen::Vector3d p = T_world_camera(head, pan, 0.5).inverse() * p_below;
    return p.x() / p.z();
  };
  EXPECT_NEAR((image_below(dq) - image_below(0)) / dq, -std::cos(0.5), 1e-3);
}

TEST(Head, RenderedImageOfACubeMovesTowardMinusXUnderPositivePan) {
  SimulatorConfig config;
  config.renderer.noise_sigma_dn = 0;
  Scene scene;
  SceneObject cube;
  cube.name = "cube";
  cube.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("cube"));
  cube.trajectory =
      std::make_shared<StaticTrajectory>(Eigen::Isometry3d(Eigen::Translation3d(1.0, 0.0, 0.0)));
  scene.objects.push_back(cube);
  Simulator sim(config, scene);
  const auto centroid = [&](double pan, double tilt) {
    (void)sim.render(0, HeadState{pan, tilt, 0, 0});
    const Renderer& r = sim.renderer();
    double sx = 0, sy = 0, n = 0;
    for (int y = 0; y < r.height(); ++y) {
      for (int x = 0; x < r.width(); ++x) {
        if (r.object_index()[static_cast<std::size_t>(y) * r.width() + x] == 0) {
          sx += x;
          sy += y;
          n += 1;
        }
      }
    }
    EXPECT_GT(n, 100);
    return Eigen::Vector2d(sx / n, sy / n);
  };
  const Eigen::Vector2d home = centroid(0, 0);
  const Eigen::Vector2d panned = centroid(0.05, 0);
  const Eigen::Vector2d tilted = centroid(0, 0.05);
  EXPECT_LT(panned.x() - home.x(), -20);  // about -f * 0.05 = -31 px
  EXPECT_NEAR(panned.y(), home.y(), 2);
  EXPECT_LT(tilted.y() - home.y(), -20);
  EXPECT_NEAR(tilted.x(), home.x(), 2);
}

TEST(Head, LookAtCentresTheTargetInTheRenderedImage) {
  SimulatorConfig config;
  config.head.p_tilt_camera_m.setZero();  // look_at is exact without offsets
  Scene scene;
  SceneObject cube;
  cube.name = "cube";
  cube.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("cube"));
  const Eigen::Vector3d target(1.2, 0.5, -0.3);
  cube.trajectory =
      std::make_shared<StaticTrajectory>(Eigen::Isometry3d(Eigen::Translation3d(target)));
  scene.objects.push_back(cube);
  Simulator sim(config, scene);
  const HeadState head = at_rest(look_at(config.head, target));
  const SimFrame frame = sim.render(0, head);
  const Eigen::Vector3d p_camera = frame.truth.objects[0].T_camera_object.translation();
  EXPECT_NEAR(p_camera.x(), 0, 1e-9);
  EXPECT_NEAR(p_camera.y(), 0, 1e-9);
  EXPECT_NEAR(p_camera.z(), target.norm(), 1e-9);
  // The centre pixel sees the cube, a corner pixel sees nothing.
  const Renderer& r = sim.renderer();
  EXPECT_EQ(r.object_index()[static_cast<std::size_t>(256) * r.width() + 256], 0);
  EXPECT_EQ(r.object_index()[0], -1);
  // Pattern schedule: frame 0 is bit 0 positive; frame 17 bit 8 negative; frame 18 cycle 1.
  EXPECT_EQ(frame.pattern.bit_index, 0);
  EXPECT_TRUE(frame.pattern.positive);
  const PatternSlot last = pattern_slot(17, 9), next = pattern_slot(18, 9);
  EXPECT_EQ(last.bit_index, 8);
  EXPECT_FALSE(last.positive);
  EXPECT_EQ(next.cycle, 1u);
  EXPECT_EQ(next.bit_index, 0);
}

TEST(Simulator, MotionBlurMixesPosesOverTheExposure) {
  SimulatorConfig config;
  config.renderer.noise_sigma_dn = 0;
  config.renderer.ambient_level = 0.5;  // the edges stand out whatever the pattern bit
  config.exposure_s = 0.01;             // long exposure so the blur spans pixels
  Scene scene;
  SceneObject cube;
  cube.name = "cube";
  cube.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("cube"));
  LateralSwingConfig swing;
  swing.T_world_object_centre = Eigen::Isometry3d(Eigen::Translation3d(1.0, 0, 0));
  swing.amplitude_m = 0.3;
  swing.peak_speed_mps = 3.0;  // ~3 cm during the exposure at full speed (~17 px at 1 m)
  const auto trajectory = std::make_shared<LateralSwingTrajectory>(swing);
  const double full_speed_s = 1.0 / trajectory->frequency_hz();  // one period in
  cube.trajectory = trajectory;
  scene.objects.push_back(cube);
  Simulator sharp(config, scene);
  config.motion_blur_samples = 8;
  Simulator blurred(config, scene);
  const SimFrame a = sharp.render(1, full_speed_s, HeadState{});
  const SimFrame b = blurred.render(1, full_speed_s, HeadState{});
  int intermediate_a = 0, intermediate_b = 0;
  const std::size_t row = static_cast<std::size_t>(256) * a.image.width;
  for (int x = 0; x < a.image.width; ++x) {
    const int va = a.image.pixels[row + x], vb = b.image.pixels[row + x];
    const int lo = 0, hi = a.image.pixels[row + 256];
    intermediate_a += (va > lo + 3 && va < hi - 3) ? 1 : 0;
    intermediate_b += (vb > lo + 3 && vb < hi - 3) ? 1 : 0;
  }
  EXPECT_LE(intermediate_a, 2);   // sharp edges
  EXPECT_GE(intermediate_b, 30);  // both edges smeared over ~19 px
}

}  // namespace
}  // namespace avs::sim
