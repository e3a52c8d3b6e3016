// The experiment scenes in launch_config/scenes/: each loads; at the head's home pose the
// target starts in view (centred, enough pixels), about 1 m away; the wall stays outside the
// 0.3-1.5 m depth window; the motions have the paper's peak speeds (sections 7.1, 7.2.1).
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "avs/sim/scene_yaml.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {
namespace {

std::string scene_path(const std::string& name) {
  const char* src = std::getenv("AVS_SOURCE_DIR");
  return std::string(src != nullptr ? src : ".") + "/launch_config/scenes/" + name + ".yaml";
}

/// Peak speed of the object's origin over [0, t_end] (1 ms steps).
double peak_speed(const Trajectory& trajectory, double t_end) {
  double peak = 0;
  for (double t = 0; t < t_end; t += 1e-3) {
    peak = std::max(peak, twist_at(trajectory, t).v_world_mps.norm());
  }
  return peak;
}

class Scenes : public ::testing::TestWithParam<const char*> {};

TEST_P(Scenes, TargetStartsInViewAboutOneMetreAwayWallOutsideTheDepthWindow) {
  SceneFile file = load_scene(scene_path(GetParam()));
  ASSERT_EQ(file.scene.objects.size(), 2u);
  const std::string target = file.scene.objects[0].name;
  EXPECT_EQ(file.scene.objects[1].name, "wall");
  Simulator sim(file.config, std::move(file.scene));
  const SimFrame frame = sim.render(0, 0.0, HeadState{});
  const ObjectTruth& o = frame.truth.objects[0];
  const Eigen::Vector3d p = o.T_camera_object.translation();
  EXPECT_NEAR(p.z(), 0.96, 0.05) << target;  // 1 m from the pan axis, camera 40 mm ahead
  EXPECT_LT(std::hypot(p.x(), p.y()) / p.z(), 0.05) << "target near the optical axis";
  const Renderer& r = sim.renderer();
  int target_pixels = 0;
  double wall_min = 1e9;
  for (int i = 0; i < r.width() * r.height(); ++i) {
    const auto idx = static_cast<std::size_t>(i);
    if (r.object_index()[idx] == 0) ++target_pixels;
    if (r.object_index()[idx] == 1)
      wall_min = std::min(wall_min, static_cast<double>(r.depth_m()[idx]));
  }
  EXPECT_GT(target_pixels, 1500) << target;
  EXPECT_GT(wall_min, 1.5) << "wall inside the depth window";
}

INSTANTIATE_TEST_SUITE_P(LaunchConfig, Scenes,
                         ::testing::Values("static_ken", "swing", "manipulator_ken",
                                           "manipulator_cube", "manipulator_cylinder"));

TEST(Scenes, SwingPeaksAtOneMetrePerSecondAcrossTheView) {
  const SceneFile file = load_scene(scene_path("swing"));
  const auto& t = *file.scene.objects[0].trajectory;
  EXPECT_NEAR(peak_speed(t, 5.0), 1.0, 0.01);
  EXPECT_NEAR(t.T_world_object(0.5 + 0.25 / (1.0 / (2 * std::numbers::pi * 0.5))).translation().y(),
              0.5, 1e-3);
}

TEST(Scenes, ManipulatorScenesPeakAtAboutOneMetrePerSecondWithinAboutTwoSeconds) {
  for (const char* name : {"manipulator_ken", "manipulator_cube", "manipulator_cylinder"}) {
    const SceneFile file = load_scene(scene_path(name));
    const auto& t = *file.scene.objects[0].trajectory;
    EXPECT_NEAR(peak_speed(t, 3.0), 1.0, 0.15) << name;
    EXPECT_TRUE(t.T_world_object(2.5).isApprox(t.T_world_object(3.0), 1e-12))
        << name << ": still moving after 2 s of motion";
  }
}

}  // namespace
}  // namespace avs::sim
