// Scene YAML adapter: every trajectory type, sensor overrides, and errors with line numbers.
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "avs/sim/scene_yaml.hpp"

namespace avs::sim {
namespace {

std::string models() {
  return std::string(std::getenv("AVS_SOURCE_DIR") ? std::getenv("AVS_SOURCE_DIR") : ".") +
         "/models";
}

std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "test.yaml", ".", models());
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(SceneYaml, ParsesObjectsTrajectoriesAndSensorSettings) {
  const SceneFile file = parse_scene(R"(
sensor: {noise_sigma_dn: 0.5, motion_blur_samples: 4, frame_rate_hz: 500}
head: {p_tilt_camera_m: [0.05, 0, 0]}
objects:
  - name: ken
    model: ken
    albedo: 0.8
    trajectory: {type: manipulator, duration_s: 3.0, start_time_s: 0.0}
  - name: cube
    model: cube
    trajectory:
      type: waypoints
      ease: true
      points:
        - {t_s: 0.0, position_m: [1, 0, 0]}
        - {t_s: 1.0, position_m: [1, 0.2, 0], rpy_deg: [0, 0, 90]}
  - name: can
    model: cylinder
    scale: 2.0
    trajectory: {type: lateral_swing, amplitude_m: 0.1, peak_speed_mps: 0.5}
  - name: wall
    plane: {width_m: 2, height_m: 1}
    trajectory: {type: static, position_m: [2, 0, 0], quaternion_wxyz: [1, 0, 0, 0]}
)",
                                     "test.yaml", ".", models());
  ASSERT_EQ(file.scene.objects.size(), 4u);
  EXPECT_DOUBLE_EQ(file.config.renderer.noise_sigma_dn, 0.5);
  EXPECT_EQ(file.config.motion_blur_samples, 4);
  EXPECT_DOUBLE_EQ(file.config.frame_rate_hz, 500);
  EXPECT_DOUBLE_EQ(file.config.head.p_tilt_camera_m.x(), 0.05);
  EXPECT_DOUBLE_EQ(file.scene.objects[0].albedo, 0.8);
  EXPECT_GT(file.scene.objects[0].mesh->triangles.size(), 1000u);
  // Manipulator over 3 s: at the end of the first half the first quarter turn is done.
  const auto& ken = *file.scene.objects[0].trajectory;
  EXPECT_NEAR(Eigen::AngleAxisd(ken.T_world_object(1.5).linear() *
                                ken.T_world_object(0).linear().transpose())
                  .angle(),
              std::numbers::pi / 2, 1e-9);
  const auto& cube = *file.scene.objects[1].trajectory;
  EXPECT_TRUE(cube.T_world_object(1.0).translation().isApprox(Eigen::Vector3d(1, 0.2, 0)));
  EXPECT_NEAR(Eigen::AngleAxisd(cube.T_world_object(1.0).linear()).angle(), std::numbers::pi / 2,
              1e-9);
  // Scaled cylinder: 160 mm across.
  float max_x = 0;
  for (const auto& v : file.scene.objects[2].mesh->vertices) max_x = std::max(max_x, v.x());
  EXPECT_NEAR(max_x, 0.08, 1e-6);
  EXPECT_EQ(file.scene.objects[3].mesh->triangles.size(), 2u);
}

TEST(SceneYaml, SensorProfileThenSingleEffectOverrides) {
  const SceneFile file = parse_scene(R"(
sensor:
  profile: realistic
  camera: {gamma: 2.2}
  projector: {black_level: 0.01}
objects:
  - {name: ken, model: ken}
)",
                                     "test.yaml", ".", models());
  const SensorEffects& e = file.config.renderer.effects;
  EXPECT_DOUBLE_EQ(e.camera.gamma, 2.2);
  EXPECT_DOUBLE_EQ(e.projector.black_level, 0.01);
  EXPECT_GT(e.camera.full_well_e, 0) << "the rest of the realistic profile stays";
  EXPECT_GT(e.projector.aperture_m, 0);
  EXPECT_GT(file.config.motion_blur_samples, 1);
  EXPECT_NE(error_of("sensor:\n  profile: sharp\n").find("test.yaml:2:"), std::string::npos);
  EXPECT_NE(error_of("sensor:\n  profile: sharp\n").find("ideal or realistic"), std::string::npos);
  EXPECT_NE(error_of("sensor:\n  camera: {gamma: -1}\n").find("gamma must be > 0"),
            std::string::npos);
}

TEST(SceneYaml, ErrorsNameFileLineAndColumn) {
  EXPECT_NE(error_of("objects:\n  - name: a\n    model: ken\n    trajectory: {type: spiral}\n")
                .find("test.yaml:4:"),
            std::string::npos);
  EXPECT_NE(error_of("objects:\n  - name: a\n    model: ken\n    trajectory: {type: spiral}\n")
                .find("unknown trajectory type 'spiral'"),
            std::string::npos);
  EXPECT_NE(
      error_of("objects:\n  - name: a\n    mesh: nowhere.stl\n").find("nowhere.stl: cannot open"),
      std::string::npos);
  EXPECT_NE(error_of("objects:\n  - name: a\n    model: ken\n    albedo: 2\n").find("test.yaml:2:"),
            std::string::npos);
  EXPECT_NE(error_of("objects: [\n").find("test.yaml:"), std::string::npos);
  EXPECT_NE(error_of("objects:\n  - name: a\n    model: ken\n    trajectory: {type: static, "
                     "position_m: [1, 2]}\n")
                .find("'position_m' must be [x, y, z]"),
            std::string::npos);
  EXPECT_NE(error_of("objects:\n  - {name: a, model: ken}\n  - {name: a, model: cube}\n")
                .find("duplicate object name 'a'"),
            std::string::npos);
}

// Found by tests/fuzz (fuzz_scene): yaml-cpp's "operator[] call on a scalar" without the file.
TEST(SceneYaml, WrongNodeKindsAreLocatedErrors) {
  EXPECT_EQ(error_of("objects:\n  - cube\n"),
            "test.yaml:2:5: an object is a map (name, model/mesh/plane, ...)");
  EXPECT_EQ(error_of("objects:\n  - {model: cube, trajectory: static}\n").rfind("test.yaml:2:", 0),
            0u);
  EXPECT_EQ(error_of("sensor: 3\nobjects: []\n").rfind("test.yaml:1:", 0), 0u);
}

}  // namespace
}  // namespace avs::sim
