// The renderer's incremental geometry pass (only the regions of objects that changed are
// redone) gives bit-identical frames and ground truth to a full pass: a persistent simulator
// against a fresh one per frame, over a sequence with a moving ken whose shadow crosses a
// static cube and the wall, an object leaving the view, a head move and repeated frames.
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {
namespace {

SceneObject object(const std::string& name, const std::string& model,
                   std::shared_ptr<const Trajectory> trajectory) {
  SceneObject o;
  o.name = name;
  o.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model(model));
  o.trajectory = std::move(trajectory);
  return o;
}

Scene test_scene() {
  Scene scene;
  ManipulatorMotionConfig motion;  // ken 1 m ahead, rotating about a pivot behind it
  motion.start_time_s = 0.0;
  motion.duration_s = 0.5;  // fast: large steps between the sampled frames
  scene.objects.push_back(object("ken", "ken", std::make_shared<ManipulatorTrajectory>(motion)));
  // A cube below and behind the ken: the ken's projector shadow (the projector is below
  // the camera) falls on it.
  scene.objects.push_back(object("cube", "cube",
                                 std::make_shared<StaticTrajectory>(
                                     Eigen::Isometry3d(Eigen::Translation3d(1.3, 0.05, -0.15)))));
  // A cylinder swinging out of the view and back.
  LateralSwingConfig swing;
  swing.T_world_object_centre = Eigen::Isometry3d(Eigen::Translation3d(1.2, 0.3, 0.2));
  swing.amplitude_m = 0.8;
  swing.peak_speed_mps = 8.0;
  scene.objects.push_back(
      object("cylinder", "cylinder", std::make_shared<LateralSwingTrajectory>(swing)));
  SceneObject wall = make_background_plane(2.0);
  wall.name = "wall";
  scene.objects.push_back(wall);
  return scene;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;  // NaN-safe
}

void expect_bit_identical_to_a_full_pass(const SimulatorConfig& config) {
  Simulator persistent(config, test_scene());
  struct Step {
    std::uint64_t frame;
    double t_s;
    HeadState head;
  };
  std::vector<Step> steps;
  for (int k = 0; k < 24; ++k)
    steps.push_back({static_cast<std::uint64_t>(k), 0.02 * k, HeadState{}});
  steps.push_back({24, 0.48, HeadState{0.03, -0.02, 0, 0}});  // head moves: everything changes
  steps.push_back({25, 0.50, HeadState{0.03, -0.02, 0, 0}});
  steps.push_back({26, 0.50, HeadState{0.03, -0.02, 0, 0}});  // nothing changes
  for (int k = 27; k < 40; ++k) {
    steps.push_back({static_cast<std::uint64_t>(k), 0.02 * k, HeadState{0.03, -0.02, 0, 0}});
  }
  int incremental_frames = 0;
  for (const Step& s : steps) {
    SCOPED_TRACE("frame " + std::to_string(s.frame));
    Simulator fresh(config, test_scene());
    const SimFrame a = persistent.render(s.frame, s.t_s, s.head);
    const SimFrame b = fresh.render(s.frame, s.t_s, s.head);
    ASSERT_EQ(a.image.pixels, b.image.pixels);
    const Renderer& ra = persistent.renderer();
    const Renderer& rb = fresh.renderer();
    EXPECT_TRUE(same_floats(ra.depth_m(), rb.depth_m()));
    EXPECT_TRUE(same_floats(ra.projector_row(), rb.projector_row()));
    EXPECT_EQ(ra.object_index(), rb.object_index());
    EXPECT_EQ(ra.code(), rb.code());
    incremental_frames += s.frame > 0 && s.frame != 24 ? 1 : 0;
  }
  EXPECT_GT(incremental_frames, 30);
}

TEST(IncrementalRender, BitIdenticalToAFullPassFrameByFrame) {
  expect_bit_identical_to_a_full_pass(SimulatorConfig{});
}

// The realistic profile's per-pixel state (texture in the object's frame, gloss, defocus
// positions) and its three sub-exposures per frame take the same incremental path.
TEST(IncrementalRender, BitIdenticalToAFullPassOnTheRealisticSensor) {
  SimulatorConfig config;
  apply_sensor_profile(SensorProfile::kRealistic, config);
  expect_bit_identical_to_a_full_pass(config);
}

TEST(IncrementalRender, MovingObjectUncoversAndShadowsStaticOnes) {
  // Direct check that the incremental path had work to do: a frame pair where the ken moved
  // changes pixels of the static wall (uncovered, shadow moved), and those match a full pass.
  SimulatorConfig config;
  config.renderer.noise_sigma_dn = 0;
  Simulator persistent(config, test_scene());
  (void)persistent.render(0, 0.10, HeadState{});
  const std::vector<std::int16_t> before = persistent.renderer().object_index();
  const SimFrame a = persistent.render(1, 0.20, HeadState{});
  Simulator fresh(config, test_scene());
  const SimFrame b = fresh.render(1, 0.20, HeadState{});
  ASSERT_EQ(a.image.pixels, b.image.pixels);
  const std::vector<std::int16_t>& after = persistent.renderer().object_index();
  int uncovered = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    uncovered += before[i] == 0 && after[i] == 3 ? 1 : 0;  // was ken, now wall
  }
  EXPECT_GT(uncovered, 100);
}

}  // namespace
}  // namespace avs::sim
