// Simulator -> decoder round trip: one 18-frame cycle of the ken in front of a wall, decoded
// by decode::RollingDecoder, gives the renderer's true depth. Checks that the simulator and
// the decoder agree on geometry, code layout, pattern order and polarity.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/sim/pattern_frame.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {
namespace {

TEST(DecodeRoundTrip, OneCycleOfTheKenDecodesToTheTrueDepth) {
  SimulatorConfig config;
  Scene scene;
  SceneObject ken;
  ken.name = "ken";
  ken.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("ken"));
  ken.trajectory = std::make_shared<StaticTrajectory>(ManipulatorMotionConfig::default_start());
  scene.objects.push_back(ken);
  scene.objects.push_back(make_background_plane(1.6));
  Simulator sim(config, scene);
  decode::DecoderConfig decoder_config;
  decoder_config.geometry = config.renderer.geometry;
  decode::RollingDecoder decoder(decoder_config);

  const HeadState head = at_rest(look_at(config.head, Eigen::Vector3d(1.0, 0, 0)));
  decode::DecodeResult result;
  const int frames = 2 * config.renderer.geometry.layout.bit_count;
  std::vector<SimFrame> kept;  // the decoder may keep views into the images
  kept.reserve(frames);
  for (int f = 0; f < frames; ++f) {
    kept.push_back(sim.render(static_cast<std::uint64_t>(f), head));
    const SimFrame& frame = kept.back();
    const decode::PatternFrame input = pattern_frame(frame);
    result = decoder.push_frame(input);
  }
  ASSERT_TRUE(result.depth_updated);
  const Renderer& r = sim.renderer();
  const std::vector<int> codes = decoder.code_map();
  long coded = 0, same_code = 0, near_code = 0;
  std::vector<double> ken_errors_m;
  for (std::size_t i = 0; i < r.depth_m().size(); ++i) {
    if (r.code()[i] < 0) continue;
    ++coded;
    same_code += codes[i] == r.code()[i] ? 1 : 0;
    near_code += std::abs(codes[i] - r.code()[i]) <= 1 ? 1 : 0;
    if (r.object_index()[i] == 0 && std::isfinite(result.depth_m[i])) {
      ken_errors_m.push_back(std::abs(result.depth_m[i] - r.depth_m()[i]));
    }
  }
  ASSERT_GT(coded, 100000);
  ASSERT_GT(ken_errors_m.size(), 1000u);
  std::sort(ken_errors_m.begin(), ken_errors_m.end());
  const double median_mm = 1000 * ken_errors_m[ken_errors_m.size() / 2];
  const double p95_mm = 1000 * ken_errors_m[ken_errors_m.size() * 95 / 100];
  std::printf(
      "coded %ld, same code %ld, within one code %ld; ken: %zu px, median %.2f mm, p95 %.2f mm\n",
      coded, same_code, near_code, ken_errors_m.size(), median_mm, p95_mm);
  EXPECT_GE(same_code, coded * 98 / 100);
  EXPECT_GE(near_code, coded * 999 / 1000);
  // One code spans 4 projector rows: about 18 mm of depth at 1 m (section 4.3: 7 mm per
  // 1.4 mm row pair), so a decoder that triangulates code centres errs by up to ~9 mm.
  EXPECT_LT(median_mm, 6.0);
  EXPECT_LT(p95_mm, 12.0);
}

/// Depth RMS of a plane facing the sensor at 1 m over the coded pixels, decoded at code centres
/// (no refinement), and the uniform-quantisation RMS there (one code's depth step / sqrt(12)).
struct PlaneResult {
  double rms_mm = 0, uniform_mm = 0;
  long valid = 0, coded = 0;
};
PlaneResult decode_plane_at_one_metre(SensorProfile profile) {
  SimulatorConfig config;
  apply_sensor_profile(profile, config);
  Scene scene;
  SceneObject plane;
  plane.name = "plane";
  plane.mesh = std::make_shared<const geometry::Mesh>(geometry::make_plane(3.0, 3.0, 1));
  plane.albedo = 0.6;
  // The plane's +z normal turned to face the camera (world -X) at 1 m along the optical axis.
  plane.trajectory = std::make_shared<StaticTrajectory>(
      Eigen::Isometry3d(Eigen::Translation3d(1.0, 0, 0) *
                        Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitY())));
  scene.objects.push_back(plane);
  Simulator sim(config, scene);
  decode::DecoderConfig decoder_config;
  decoder_config.geometry = config.renderer.geometry;
  decode::RollingDecoder decoder(decoder_config);
  const HeadState head;  // optical axis along world X
  decode::DecodeResult result;
  std::vector<SimFrame> kept;
  const int frames = 2 * config.renderer.geometry.layout.bit_count;
  kept.reserve(frames);
  for (int f = 0; f < frames; ++f) {
    kept.push_back(sim.render(static_cast<std::uint64_t>(f), head));
    result = decoder.push_frame(pattern_frame(kept.back()));
  }
  EXPECT_TRUE(result.depth_updated);
  const Renderer& r = sim.renderer();
  PlaneResult out;
  double sum = 0;
  for (std::size_t i = 0; i < r.depth_m().size(); ++i) {
    if (r.code()[i] < 0) continue;
    ++out.coded;
    if (!std::isfinite(result.depth_m[i])) continue;
    ++out.valid;
    const double e = 1e3 * (result.depth_m[i] - r.depth_m()[i]);
    sum += e * e;
  }
  out.rms_mm = std::sqrt(sum / std::max(out.valid, 1L));
  const int width = r.width(), centre = (r.height() / 2) * width + width / 2;
  const int code = r.code()[static_cast<std::size_t>(centre)];
  out.uniform_mm =
      1e3 *
      std::abs(decoder.table().depth(centre, code + 1) - decoder.table().depth(centre, code)) /
      std::sqrt(12.0);
  return out;
}

// Issue 19's plane goal: under the realistic sensor the depth RMS of a plane at 1 m stays within
// 1.25 x the quantisation figure without refinement (defocus and noise must not cost codes).
TEST(DecodeRoundTrip, PlaneAtOneMetreOnTheRealisticSensorStaysAtQuantisation) {
  const PlaneResult ideal = decode_plane_at_one_metre(SensorProfile::kIdeal);
  const PlaneResult realistic = decode_plane_at_one_metre(SensorProfile::kRealistic);
  std::printf(
      "plane at 1 m, code centres: ideal RMS %.2f mm (%ld of %ld coded valid), realistic "
      "%.2f mm (%ld of %ld); uniform quantisation %.2f mm\n",
      ideal.rms_mm, ideal.valid, ideal.coded, realistic.rms_mm, realistic.valid, realistic.coded,
      realistic.uniform_mm);
  EXPECT_GT(realistic.coded, 150000);
  // Defocus blurs each stripe edge, so a pixel on the edge of a bit sees |I_pos - I_neg| below
  // Eq. 2's threshold there and is left out: 3.4 % of the coded pixels at 1 m (one code is 2.3
  // camera pixels; every code boundary is an edge of one bit). The ideal renderer's point
  // samples are never on an edge.
  EXPECT_GE(realistic.valid, realistic.coded * 95 / 100);
  EXPECT_EQ(ideal.valid, ideal.coded);
  EXPECT_LE(ideal.rms_mm, 1.25 * ideal.uniform_mm);
  EXPECT_LE(realistic.rms_mm, 1.25 * realistic.uniform_mm);
}

}  // namespace
}  // namespace avs::sim
