// Rolling decode (section 4.3): equality with the full-cycle decode, dropped and out-of-order
// frames.
#include <cmath>

#include <gtest/gtest.h>

#include "avs/decode/synthetic_plane.hpp"

namespace avs::decode {
namespace {

constexpr int kBits = 9;

PlaneSceneConfig scene_config(std::uint32_t seed, double depth_m = 1.0) {
  PlaneSceneConfig c;
  c.seed = seed;
  c.plane_depth_m = depth_m;
  c.noise_sigma = 4.0;  // enough noise that some pixels are ambiguous
  return c;
}

// NaN-aware bitwise equality of two depth maps; returns the number of differing pixels.
int count_differences(std::span<const float> a, std::span<const float> b) {
  int differences = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const bool same = (std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i];
    differences += !same;
  }
  return differences;
}

int count_valid(std::span<const float> depth) {
  int valid = 0;
  for (float z : depth) valid += !std::isnan(z);
  return valid;
}

TEST(RollingDecoder, NineUpdatesEqualTheFullCycleDecode) {
  const DecoderConfig config;
  const auto scene = render_plane(config.geometry, scene_config(11));
  RollingDecoder decoder(config);
  std::vector<PatternFrame> frames;
  for (int k = 0; k < kBits; ++k) {
    for (Polarity p : {Polarity::kPositive, Polarity::kNegative}) {
      frames.push_back(scene.frame(k, p, 0));
      const DecodeResult result = decoder.push_frame(frames.back());
      EXPECT_EQ(result.depth_updated, p == Polarity::kNegative);
      if (p == Polarity::kNegative && k < kBits - 1) {
        EXPECT_EQ(count_valid(result.depth_m), 0)
            << "window incomplete after " << k + 1 << " updates";
      }
    }
  }
  const FullCycleResult full = decode_full_cycle(config, frames);
  const DecodeResult last =
      decoder.push_frame(scene.frame(kBits - 1, Polarity::kNegative, 0));  // repeat
  EXPECT_FALSE(last.depth_updated);
  EXPECT_EQ(last.stats.out_of_order_frames, 1);
  EXPECT_GT(count_valid(last.depth_m), 200000);
  EXPECT_EQ(count_differences(last.depth_m, full.depth_m), 0);
  EXPECT_EQ(decoder.code_map(), full.code);
}

TEST(RollingDecoder, NineUpdatesEqualTheFullCycleDecodeWithSubcodeRefinement) {
  DecoderConfig config;
  config.subcode_half_window = 4;
  const auto scene = render_plane(config.geometry, scene_config(12));
  RollingDecoder decoder(config);
  std::vector<PatternFrame> frames;
  DecodeResult result;
  for (int k = 0; k < kBits; ++k) {
    frames.push_back(scene.frame(k, Polarity::kPositive, 0));
    frames.push_back(scene.frame(k, Polarity::kNegative, 0));
    decoder.push_frame(frames[frames.size() - 2]);
    result = decoder.push_frame(frames.back());
  }
  const FullCycleResult full = decode_full_cycle(config, frames);
  EXPECT_GT(count_valid(result.depth_m), 200000);
  EXPECT_EQ(count_differences(result.depth_m, full.depth_m), 0);
  // Refined depth differs from the code-centre depth (else the option did nothing).
  const FullCycleResult plain = decode_full_cycle(DecoderConfig{}, frames);
  EXPECT_GT(count_differences(result.depth_m, plain.depth_m), 100000);
}

TEST(RollingDecoder, SubcodeRefinementIsForTheTableOnly) {
  DecoderConfig config;
  config.subcode_half_window = 4;
  config.triangulation = TriangulationMethod::kReferenceSolve;
  EXPECT_THROW(RollingDecoder{config}, std::invalid_argument);
}

TEST(RollingDecoder, WindowAcrossCyclesEqualsFullDecodeOfTheSameFrames) {
  // Bits 4..8 of cycle 0 from one capture, bits 0..3 of cycle 1 from another (new noise, plane
  // moved to 1.02 m): after 9 updates the map is the full decode of exactly those frames.
  DecoderConfig config;
  config.code_correction = true;
  const auto a = render_plane(config.geometry, scene_config(21, 1.0));
  const auto b = render_plane(config.geometry, scene_config(22, 1.02));
  RollingDecoder decoder(config);
  std::vector<PatternFrame> window;
  DecodeResult result;
  for (int step = 0; step < kBits; ++step) {
    const int k = (4 + step) % kBits;
    const auto& scene = k >= 4 ? a : b;
    const std::int64_t cycle = k >= 4 ? 0 : 1;
    window.push_back(scene.frame(k, Polarity::kPositive, cycle));
    window.push_back(scene.frame(k, Polarity::kNegative, cycle));
    decoder.push_frame(window[window.size() - 2]);
    result = decoder.push_frame(window.back());
  }
  DecoderConfig no_correction = config;
  no_correction.code_correction = false;
  const FullCycleResult full = decode_full_cycle(no_correction, window);
  EXPECT_GT(count_valid(result.depth_m), 150000);
  EXPECT_EQ(count_differences(result.depth_m, full.depth_m), 0);
  EXPECT_EQ(result.cycle, 1);
  EXPECT_EQ(result.bit_index, 3);
}

// Feeds cycle 0 completely, then cycle 1 with the negative of bit `lost_bit` missing.
struct DropRun {
  std::vector<int> valid_after_update;  ///< cycle 1 updates, then cycle 2 updates
  DecoderStats stats;
  std::vector<float> final_depth;
};

DropRun run_with_dropped_negative(DecoderConfig config, int lost_bit) {
  const auto scene = render_plane(config.geometry, scene_config(31));
  RollingDecoder decoder(config);
  for (int k = 0; k < kBits; ++k) {
    decoder.push_frame(scene.frame(k, Polarity::kPositive, 0));
    decoder.push_frame(scene.frame(k, Polarity::kNegative, 0));
  }
  DropRun run;
  for (std::int64_t cycle = 1; cycle <= 2; ++cycle) {
    for (int k = 0; k < kBits; ++k) {
      decoder.push_frame(scene.frame(k, Polarity::kPositive, cycle));
      if (cycle == 1 && k == lost_bit) continue;
      const DecodeResult r = decoder.push_frame(scene.frame(k, Polarity::kNegative, cycle));
      EXPECT_TRUE(r.depth_updated);
      run.valid_after_update.push_back(count_valid(r.depth_m));
    }
  }
  run.stats = decoder.stats();
  run.final_depth.assign(decoder.push_frame(scene.frame(0, Polarity::kPositive, 3)).depth_m.begin(),
                         decoder.push_frame(scene.frame(0, Polarity::kPositive, 3)).depth_m.end());
  return run;
}

TEST(RollingDecoder, DroppedFrameInvalidatesOnlyItsBitWhileItIsInTheWindow) {
  const int lost_bit = 4;
  const DropRun run = run_with_dropped_negative(DecoderConfig{}, lost_bit);
  EXPECT_EQ(run.stats.dropped_frames, 1);
  EXPECT_EQ(run.stats.incomplete_pairs, 0);  // the positive that follows is the next pair's
  ASSERT_EQ(run.valid_after_update.size(), 2u * kBits - 1);
  // Cycle 1 updates 0..3 still have a complete window (bit 4 of cycle 0 is young enough).
  for (int u = 0; u < lost_bit; ++u) EXPECT_GT(run.valid_after_update[u], 200000) << "update " << u;
  // From bit 5 of cycle 1 until bit 4 of cycle 2 is measured, the window lacks bit 4.
  for (int u = lost_bit; u < lost_bit + kBits - 1; ++u)
    EXPECT_EQ(run.valid_after_update[u], 0) << "update " << u;
  // ...and not one update longer: valid again as soon as bit 4 is re-measured.
  for (std::size_t u = lost_bit + kBits - 1; u < run.valid_after_update.size(); ++u) {
    EXPECT_GT(run.valid_after_update[u], 200000) << "update " << u;
  }
}

TEST(RollingDecoder, RelaxedBitAgeKeepsTheMapThroughADrop) {
  DecoderConfig config;
  config.max_bit_age_pairs = 2 * kBits;
  const DropRun run = run_with_dropped_negative(config, 4);
  for (std::size_t u = 0; u < run.valid_after_update.size(); ++u) {
    EXPECT_GT(run.valid_after_update[u], 200000) << "update " << u;
  }
}

TEST(RollingDecoder, OutOfOrderFramesAreNeverAssignedToAnotherBit) {
  // Scene A in cycle 0, a different depth (scene B) in cycle 1. In cycle 1 the frames of bit 2
  // arrive after those of bit 3. If bits were placed by arrival order the codes would be wrong;
  // they must instead be discarded (counted) and the map must keep to the frames' own bits.
  const DecoderConfig config;
  const auto a = render_plane(config.geometry, scene_config(41, 1.0));
  const auto b = render_plane(config.geometry, scene_config(42, 1.0));
  RollingDecoder decoder(config);
  for (int k = 0; k < kBits; ++k) {
    decoder.push_frame(a.frame(k, Polarity::kPositive, 0));
    decoder.push_frame(a.frame(k, Polarity::kNegative, 0));
  }
  const std::vector<int> order = {0, 1, 3, 2, 4, 5, 6, 7, 8};
  for (int k : order) {
    decoder.push_frame(b.frame(k, Polarity::kPositive, 1));
    decoder.push_frame(b.frame(k, Polarity::kNegative, 1));
  }
  EXPECT_EQ(decoder.stats().out_of_order_frames, 2);
  EXPECT_EQ(decoder.stats().dropped_frames, 2);
  EXPECT_EQ(decoder.stats().pairs_decoded, 2 * kBits - 1);
  // Bit 2 was lost for cycle 1, so the strict window is incomplete.
  EXPECT_TRUE(decoder.code_map() == std::vector<int>(decoder.code_map().size(), -1));
  // Re-measure bit 2 in cycle 2 (a swapped positive/negative arrival is out of order too).
  decoder.push_frame(b.frame(0, Polarity::kPositive, 2));
  decoder.push_frame(b.frame(0, Polarity::kNegative, 2));
  decoder.push_frame(b.frame(1, Polarity::kNegative, 2));  // positive lost
  EXPECT_EQ(decoder.stats().incomplete_pairs, 1);
  decoder.push_frame(b.frame(2, Polarity::kNegative, 2));
  decoder.push_frame(b.frame(2, Polarity::kPositive, 2));  // late: discarded
  EXPECT_EQ(decoder.stats().out_of_order_frames, 3);
  decoder.push_frame(b.frame(2, Polarity::kPositive, 3));
  // Valid codes, wherever present, are the true ones (within noise: at most 1 off).
  const std::vector<int> codes = decoder.code_map();
  int valid = 0, wrong = 0;
  for (std::size_t i = 0; i < codes.size(); ++i) {
    if (codes[i] < 0) continue;
    ++valid;
    wrong += std::abs(codes[i] - b.true_code[i]) > 1;
  }
  EXPECT_EQ(valid, 0);  // bit 1 and 2 of cycle 2 are missing: no complete window yet
  EXPECT_EQ(wrong, 0);
}

TEST(RollingDecoder, AfterDisorderTheMapRecoversWithCorrectCodes) {
  const DecoderConfig config;
  const auto a = render_plane(config.geometry, scene_config(51, 1.0));
  RollingDecoder decoder(config);
  // Cycle 0 with bits 5 and 6 swapped, cycle 1 in order.
  for (int k : {0, 1, 2, 3, 4, 6, 5, 7, 8}) {
    decoder.push_frame(a.frame(k, Polarity::kPositive, 0));
    decoder.push_frame(a.frame(k, Polarity::kNegative, 0));
  }
  DecodeResult r;
  for (int k = 0; k < kBits; ++k) {
    decoder.push_frame(a.frame(k, Polarity::kPositive, 1));
    r = decoder.push_frame(a.frame(k, Polarity::kNegative, 1));
  }
  std::vector<PatternFrame> cycle1;
  for (int k = 0; k < kBits; ++k) {
    cycle1.push_back(a.frame(k, Polarity::kPositive, 1));
    cycle1.push_back(a.frame(k, Polarity::kNegative, 1));
  }
  const FullCycleResult full = decode_full_cycle(config, cycle1);
  EXPECT_EQ(count_differences(r.depth_m, full.depth_m), 0);
  EXPECT_GT(count_valid(r.depth_m), 200000);
}

TEST(RollingDecoder, DepthIntoACallersBufferEqualsItsOwn) {
  // push_frame(frame, depth_out) (the decode component writes straight into its message).
  const DecoderConfig config;
  const auto scene = render_plane(config.geometry, scene_config(61));
  RollingDecoder own(config);
  RollingDecoder external(config);
  std::vector<float> out(static_cast<std::size_t>(scene.width) * scene.height, 0.0f);
  int compared = 0;
  for (int cycle = 0; cycle < 2; ++cycle) {
    for (int k = 0; k < kBits; ++k) {
      for (Polarity polarity : {Polarity::kPositive, Polarity::kNegative}) {
        const PatternFrame frame = scene.frame(k, polarity, cycle);
        const DecodeResult a = own.push_frame(frame);
        std::fill(out.begin(), out.end(), 0.0f);
        const DecodeResult b = external.push_frame(frame, out);
        ASSERT_EQ(a.depth_updated, b.depth_updated);
        if (!b.depth_updated) continue;
        ASSERT_EQ(b.depth_m.data(), out.data());
        EXPECT_EQ(count_differences(a.depth_m, out), 0) << "cycle " << cycle << " bit " << k;
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 2 * kBits);
  EXPECT_GT(count_valid(out), scene.width * scene.height / 2);
  std::vector<float> wrong_size(10);
  EXPECT_THROW(external.push_frame(scene.frame(0, Polarity::kNegative, 5), wrong_size),
               std::invalid_argument);
}

TEST(RollingDecoder, RejectsFramesThatDoNotFit) {
  const DecoderConfig config;
  RollingDecoder decoder(config);
  std::vector<std::uint8_t> small(16 * 16);
  EXPECT_THROW(
      decoder.push_frame(PatternFrame{{small.data(), 16, 16, 16}, 0, Polarity::kPositive, 0}),
      std::invalid_argument);
  std::vector<std::uint8_t> image(512 * 512);
  EXPECT_THROW(
      decoder.push_frame(PatternFrame{{image.data(), 512, 512, 512}, 9, Polarity::kPositive, 0}),
      std::invalid_argument);
}

// Issue 20 section 5: the pattern source restarts (its process killed and started again) and
// counts its cycles from 0 again. Its frames are not "late": the decoder starts over with them
// and gives the new stream's depth after one whole cycle, instead of discarding every frame
// until the new counter passes the old one.
TEST(RollingDecoder, ASourceThatStartsAgainIsDecodedAfterOneCycle) {
  const DecoderConfig config;
  const auto a = render_plane(config.geometry, scene_config(51, 1.0));
  const auto b = render_plane(config.geometry, scene_config(52, 0.8));
  RollingDecoder decoder(config);
  for (int cycle = 100; cycle < 103; ++cycle) {
    for (int k = 0; k < kBits; ++k) {
      decoder.push_frame(a.frame(k, Polarity::kPositive, cycle));
      decoder.push_frame(a.frame(k, Polarity::kNegative, cycle));
    }
  }
  EXPECT_EQ(decoder.stats().source_restarts, 0);
  // A frame one cycle late is late, not a restart.
  decoder.push_frame(a.frame(0, Polarity::kPositive, 101));
  EXPECT_EQ(decoder.stats().out_of_order_frames, 1);
  EXPECT_EQ(decoder.stats().source_restarts, 0);
  DecodeResult result;
  for (int k = 0; k < kBits; ++k) {
    decoder.push_frame(b.frame(k, Polarity::kPositive, 0));
    result = decoder.push_frame(b.frame(k, Polarity::kNegative, 0));
    EXPECT_TRUE(result.depth_updated) << "bit " << k;
    if (k < kBits - 1) {
      EXPECT_EQ(count_valid(result.depth_m), 0) << "old bits mixed into the new stream, bit " << k;
    }
  }
  EXPECT_EQ(decoder.stats().source_restarts, 1);
  EXPECT_EQ(decoder.stats().out_of_order_frames, 1);
  EXPECT_EQ(decoder.stats().frames_received, 3 * 2 * kBits + 1 + 2 * kBits);
  // The new stream's depth (0.8 m), not the old one's (1 m).
  int valid = 0, near_08 = 0;
  for (float z : result.depth_m) {
    if (std::isnan(z)) continue;
    ++valid;
    near_08 += std::abs(z - 0.8F) < 0.01F;
  }
  EXPECT_GT(valid, 200000);
  EXPECT_GT(near_08, valid * 99 / 100);
}

}  // namespace
}  // namespace avs::decode
