// Issue 14, section 2 (`avs calib capture --source camera`): the ViewAssembler finds the
// calibration sequence in a stream of camera frames at any phase and never hands out a view
// whose frames are mislabelled: simulated board views (the renderer of `avs calib capture
// --source sim`), streamed as a camera would give them.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/calib/bench.hpp"
#include "avs/calib/view_assembler.hpp"

namespace avs::calib {
namespace {

struct Views {
  Views() {
    sim::RendererConfig renderer;
    renderer.geometry = bench_truth_geometry();
    renderer.noise_sigma_dn = 2.0;
    SimCapture capture(renderer, board);
    info = capture.info();
    const auto poses = generate_board_poses(renderer.geometry, board, 2, 0.6, 1.0, 20, 14);
    a = capture.render(poses[0], 0, "a");
    a_again = capture.render(poses[0], 1, "a");  // the same pose, other noise: the next cycle
    b = capture.render(poses[1], 2, "b");
  }
  sim::Checkerboard board;
  CaptureInfo info;
  BoardView a, a_again, b;
};

const Views& views() {
  static const Views v;
  return v;
}

decode::ImageView8 view_of(const decode::GrayImage8& image) {
  return {image.pixels.data(), image.width, image.height, 0};
}

/// Streams frames with ids from `first_id`; returns the first view assembled (and the
/// rejections seen on the way).
struct Fed {
  std::optional<BoardView> view;
  std::vector<std::string> rejected;
  std::uint64_t next_id = 0;
};
Fed feed(ViewAssembler& assembler, const std::vector<const decode::GrayImage8*>& frames,
         std::uint64_t first_id) {
  Fed fed;
  fed.next_id = first_id;
  for (const decode::GrayImage8* f : frames) {
    AssemblerResult r = assembler.push(fed.next_id, view_of(*f));
    fed.next_id = fed.next_id == 65535 ? 1 : fed.next_id + 1;  // GigE Vision ids skip 0
    if (!r.rejected.empty()) fed.rejected.push_back(r.rejected);
    if (r.view) {
      fed.view = std::move(r.view);
      return fed;
    }
  }
  return fed;
}

/// One view as the projector shows it: white kWhiteFrames times, then black and the codes.
std::vector<const decode::GrayImage8*> projected(const BoardView& view) {
  std::vector<const decode::GrayImage8*> out(kWhiteFrames, &view.frames[0]);
  for (std::size_t f = 1; f < view.frames.size(); ++f) out.push_back(&view.frames[f]);
  return out;
}

/// Projected cycles of `cycles` (one BoardView each), from frame `phase` of the first.
std::vector<const decode::GrayImage8*> stream(const std::vector<const BoardView*>& cycles,
                                              std::size_t phase) {
  std::vector<const decode::GrayImage8*> out;
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    const std::vector<const decode::GrayImage8*> cycle = projected(*cycles[c]);
    out.insert(out.end(), cycle.begin() + static_cast<std::ptrdiff_t>(c == 0 ? phase : 0),
               cycle.end());
  }
  return out;
}

void expect_frames_equal(const BoardView& got, const BoardView& want) {
  ASSERT_EQ(got.frames.size(), want.frames.size());
  for (std::size_t f = 0; f < want.frames.size(); ++f) {
    EXPECT_EQ(got.frames[f].pixels, want.frames[f].pixels) << "frame " << f;
  }
}

TEST(ViewAssembler, FindsTheSequenceAtEveryPhaseAcrossAnIdWrap) {
  const Views& v = views();
  ASSERT_EQ(v.a.frames.size(), 36u);  // white, black, 8 column bits and 9 row bits, each +/-
  const std::size_t n = projection_sequence(v.info.codes).size();
  ASSERT_EQ(n, 38u);  // white three times
  for (std::size_t phase = 0; phase < n; ++phase) {
    ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
    // A cycle of the previous pose's last frames, then this pose's cycles; ids wrap 65535 -> 1.
    const Fed fed =
        feed(assembler, stream({&v.a, &v.a_again, &v.a, &v.a_again}, phase), 65535 - 20);
    ASSERT_TRUE(fed.view) << "phase " << phase;
    // The first whole cycle from a white frame.
    expect_frames_equal(*fed.view, phase == 0 ? v.a : v.a_again);
  }
}

TEST(ViewAssembler, AGapInTheIdsStartsAgainAndNeverShiftsTheLabels) {
  const Views& v = views();
  ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
  std::vector<const decode::GrayImage8*> frames = stream({&v.a, &v.a_again, &v.a, &v.a_again}, 7);
  // Frame 40 lost in transport (its id never arrives): the ids say so.
  std::optional<BoardView> got;
  std::vector<std::string> rejected;
  std::uint64_t id = 100;
  for (std::size_t k = 0; k < frames.size() && !got; ++k, ++id) {
    if (k == 40) continue;
    AssemblerResult r = assembler.push(id, view_of(*frames[k]));
    if (!r.rejected.empty()) rejected.push_back(r.rejected);
    got = std::move(r.view);
  }
  ASSERT_TRUE(got);
  ASSERT_FALSE(rejected.empty());
  EXPECT_NE(rejected[0].find("frames lost"), std::string::npos) << rejected[0];
  // The run after the gap starts in the second cycle (frame 40 is its frame 9); its first
  // white is the third cycle's.
  expect_frames_equal(*got, v.a);
}

TEST(ViewAssembler, AFrameSlippedWithoutATraceInTheIdsIsCaughtByThePairs) {
  const Views& v = views();
  ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
  // Frame 10 of each cycle lost, but the ids count on (a camera that missed a trigger and
  // numbered the next exposure as if nothing happened): every cycle is one frame short.
  std::vector<const decode::GrayImage8*> frames;
  for (const BoardView* c : {&v.a, &v.a_again, &v.a, &v.a_again}) {
    const std::vector<const decode::GrayImage8*> cycle = projected(*c);
    for (std::size_t f = 0; f < cycle.size(); ++f) {
      if (f != 10) frames.push_back(cycle[f]);
    }
  }
  const Fed fed = feed(assembler, frames, 1);
  EXPECT_FALSE(fed.view);
  ASSERT_FALSE(fed.rejected.empty());
  EXPECT_NE(fed.rejected[0].find("not the complementary pair"), std::string::npos)
      << fed.rejected[0];
}

TEST(ViewAssembler, ABoardMovedDuringTheCaptureIsRefusedThenTheStillOneTaken) {
  const Views& v = views();
  ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
  // Pose a for one cycle, then pose b (the board moved) for three.
  const Fed fed = feed(assembler, stream({&v.a, &v.b, &v.b, &v.b}, 0), 1);
  ASSERT_FALSE(fed.rejected.empty());
  EXPECT_NE(fed.rejected[0].find("scene changed"), std::string::npos) << fed.rejected[0];
  ASSERT_TRUE(fed.view);
  expect_frames_equal(*fed.view, v.b);
}

TEST(ViewAssembler, NoProjectedSequenceGivesNoViewAndSaysWhy) {
  const Views& v = views();
  ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
  // The projector off: the camera sees the black frame over and over.
  std::vector<const decode::GrayImage8*> frames(200, &v.a.frames[1]);
  const Fed fed = feed(assembler, frames, 1);
  EXPECT_FALSE(fed.view);
  ASSERT_FALSE(fed.rejected.empty());
  EXPECT_NE(fed.rejected[0].find("calibration sequence"), std::string::npos) << fed.rejected[0];
  // A frame of another size, or with rows shorter than its width, is refused with its size.
  const std::vector<std::uint8_t> small(64 * 64);
  const AssemblerResult r = assembler.push(999, {small.data(), 64, 64, 0});
  EXPECT_NE(r.rejected.find("64 x 64"), std::string::npos) << r.rejected;
  const AssemblerResult s = assembler.push(1000, {v.a.frames[0].pixels.data(), 512, 512, 100});
  EXPECT_NE(s.rejected.find("rows of 100 bytes"), std::string::npos) << s.rejected;
  const AssemblerResult t = assembler.push(1001, {v.a.frames[0].pixels.data(), 512, 512, -512});
  EXPECT_FALSE(t.rejected.empty());
}

TEST(ViewAssembler, ACodeBitThatLooksLikeWhiteThenBlackDoesNotShiftTheLabels) {
  const Views& v = views();
  // Column bit 0 positive shows what white shows and its negative what black shows (a scene
  // inside one half of the projector's image): with a single white frame this pair would
  // start a sequence as well as the true white and black do (every pair after it is a true
  // pair); three white frames cannot come from code frames.
  BoardView odd = v.a;
  odd.frames[2] = v.a.frames[0];
  odd.frames[3] = v.a.frames[1];
  BoardView odd_again = v.a_again;
  odd_again.frames[2] = v.a_again.frames[0];
  odd_again.frames[3] = v.a_again.frames[1];
  for (const std::size_t phase : {0u, 5u, 20u}) {
    ViewAssembler assembler(v.info.codes, v.info.camera_width, v.info.camera_height);
    const Fed fed = feed(assembler, stream({&odd, &odd_again, &odd, &odd_again}, phase), 1);
    ASSERT_TRUE(fed.view) << "phase " << phase;
    expect_frames_equal(*fed.view, phase == 0 ? odd : odd_again);
  }
}

TEST(StampedFrameIds, StepsOfWholePeriodsAreIdsOffGridFramesAreLeftOutANewGridIsTaken) {
  constexpr std::int64_t kMs = 1000000;
  StampedFrameIds ids(kMs);
  std::string why;
  EXPECT_EQ(ids.id(5 * kMs, why), 1u);
  EXPECT_EQ(ids.id(6 * kMs + kMs / 5, why), 2u);  // jitter within a quarter period
  EXPECT_EQ(ids.id(9 * kMs, why), 5u);            // two frames lost: the ids say so
  EXPECT_FALSE(ids.id(9 * kMs + kMs / 2, why));   // an extra exposure off the grid
  EXPECT_NE(why.find("not a whole number of pattern periods"), std::string::npos) << why;
  EXPECT_EQ(ids.id(10 * kMs, why), 6u);  // the grid goes on
  EXPECT_FALSE(ids.id(10 * kMs, why));   // not after the last one
  // The sequence restarted half a period later: two frames off the grid, then the grid moves
  // with a jump in the ids.
  EXPECT_FALSE(ids.id(11 * kMs + kMs / 2, why));
  EXPECT_FALSE(ids.id(12 * kMs + kMs / 2, why));
  EXPECT_EQ(ids.id(13 * kMs + kMs / 2, why), 8u);
  EXPECT_EQ(ids.id(14 * kMs + kMs / 2, why), 9u);
}

TEST(RepeatedReasons, SaysAReasonOnceAndHowOftenItCameInARow) {
  std::vector<std::string> log;
  RepeatedReasons reasons([&](const std::string& line) { log.push_back(line); });
  reasons.add("frame id 12 after 9: frames lost");
  reasons.add("frame id 40 after 37: frames lost");
  reasons.add("frame id 90 after 81: frames lost");
  reasons.add("the scene changed");
  reasons.flush();
  EXPECT_EQ(log, (std::vector<std::string>{"frame id 12 after 9: frames lost",
                                           "(the same 3 times in a row)", "the scene changed"}));
  EXPECT_EQ(reasons.total(), 4);
  EXPECT_EQ(reasons.last(), "the scene changed");
}

TEST(ProjectorPattern, IsWhatTheSimulatorsProjectorShows) {
  const CaptureCodes codes = calibration_codes(912, 1140, 4);
  const std::vector<FrameId> frames = capture_frames(codes);
  const std::vector<FrameId> projected = projection_sequence(codes);
  ASSERT_EQ(projected.size(), frames.size() + kWhiteFrames - 1);
  for (std::size_t k = 0; k < kWhiteFrames; ++k) EXPECT_EQ(projected[k].kind, FrameKind::kWhite);
  EXPECT_EQ(projected[kWhiteFrames].kind, FrameKind::kBlack);
  const decode::GrayImage8 white = projector_pattern(codes, frames[0]);
  const decode::GrayImage8 black = projector_pattern(codes, frames[1]);
  EXPECT_EQ(white.width, 912);
  EXPECT_EQ(white.height, 1140);
  EXPECT_EQ(std::count(white.pixels.begin(), white.pixels.end(), 255), 912 * 1140);
  EXPECT_EQ(std::count(black.pixels.begin(), black.pixels.end(), 0), 912 * 1140);
  // Column bit 0 (MSB) splits the coded columns in two halves; its negative lights the rest of
  // the coded columns; the row code varies along y only.
  const decode::GrayImage8 c0p = projector_pattern(codes, frames[2]);
  const decode::GrayImage8 c0n = projector_pattern(codes, frames[3]);
  const int x_low = codes.columns.first_row + 1,
            x_high = codes.columns.first_row + codes.columns.used_rows() - 2;
  EXPECT_NE(c0p.pixels[x_low], c0p.pixels[x_high]);
  EXPECT_EQ(c0p.pixels[x_low] + c0n.pixels[x_low], 255);
  const FrameId row_bit{FrameKind::kRowBit, codes.rows.bit_count - 1, true};
  const decode::GrayImage8 r = projector_pattern(codes, row_bit);
  for (int y = 0; y < r.height; y += 37) {
    EXPECT_EQ(r.pixels[static_cast<std::size_t>(y) * 912],
              r.pixels[static_cast<std::size_t>(y) * 912 + 600]);
  }
}

}  // namespace
}  // namespace avs::calib
