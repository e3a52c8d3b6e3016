#include <gtest/gtest.h>

#include "avs/decode/calibration_yaml.hpp"

namespace avs::decode {
namespace {

TEST(CalibrationYaml, RoundTripsTheDefaultGeometry) {
  SensorGeometry g = default_sensor_geometry();
  g.camera.k1 = -0.1;
  g.projector.p2 = 0.002;
  const SensorGeometry back = parse_sensor_geometry_yaml(sensor_geometry_to_yaml(g));
  EXPECT_EQ(back.camera.width, 512);
  EXPECT_DOUBLE_EQ(back.camera.fx_px, g.camera.fx_px);
  EXPECT_DOUBLE_EQ(back.camera.k1, -0.1);
  EXPECT_DOUBLE_EQ(back.projector.p2, 0.002);
  EXPECT_TRUE(back.R_projector_camera.isApprox(g.R_projector_camera, 1e-15));
  EXPECT_TRUE(back.t_projector_camera_m.isApprox(g.t_projector_camera_m, 1e-15));
  EXPECT_EQ(back.layout.first_row, 40);
}

TEST(CalibrationYaml, ErrorsNameSourceAndLine) {
  try {
    parse_sensor_geometry_yaml("camera:\n  width: 512\n  focal: 3\n", "calib.yaml");
    FAIL() << "unknown key accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calib.yaml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("focal"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_sensor_geometry_yaml("R_projector_camera: [1, 0, 0, 0, 2, 0, 0, 0, 1]\n"),
               std::runtime_error);
  EXPECT_THROW(parse_sensor_geometry_yaml("t_projector_camera_m: [1, 2]\n"), std::runtime_error);
  EXPECT_THROW(load_sensor_geometry_yaml("/nonexistent/calib.yaml"), std::runtime_error);
}

// Found by tests/fuzz (fuzz_calibration): a list as a key gave yaml-cpp's "bad conversion"
// without the file.
TEST(CalibrationYaml, ListAsAKeyIsALocatedError) {
  try {
    parse_sensor_geometry_yaml("camera: {fx: 600,\n  [1, 2]}\n", "calib.yaml");
    FAIL() << "a list as a key accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "calib.yaml:2:3: a key in camera is not a name");
  }
}

}  // namespace
}  // namespace avs::decode
