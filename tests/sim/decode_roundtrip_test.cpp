// Simulator -> decoder round trip: one 18-frame cycle of the ken in front of a wall, decoded
// by decode::RollingDecoder, gives the renderer's true depth. Checks that the simulator and
// the decoder agree on geometry, code layout, pattern order and polarity.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/pattern_frame.hpp"
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

}  // namespace
}  // namespace avs::sim
