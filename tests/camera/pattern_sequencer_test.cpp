// PatternSequencer against true labels: synthetic Gray-code frames of a plane (decode's
// render_plane, the decoder's own geometry, seeded noise) delivered as a camera would, with
// frame ids and timestamps, through drops, bursts, duplicates, id wraps, a camera restart, a
// late projector and exposure slips. Every labelled frame must carry its true bit and polarity,
// and its sequence number (cycle * 2n + slot) must advance at least as far as the projector's
// (exactly as far while the lock holds), so the decoder never combines mislabelled bits.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "avs/camera/pattern_sequencer.hpp"
#include "avs/decode/synthetic_plane.hpp"

namespace avs::camera {
namespace {

using decode::Polarity;

constexpr int kBits = 9;
constexpr int kFramesPerCycle = 2 * kBits;
constexpr std::int64_t kPeriodNs = 1'000'000;

const decode::SyntheticScene& scene() {
  static const decode::SyntheticScene s = [] {
    decode::PlaneSceneConfig c;
    c.plane_depth_m = 1.0;
    c.noise_sigma = 3.0;
    c.seed = 15;
    c.shadow_x0 = 100;
    c.shadow_x1 = 180;
    c.shadow_y0 = 300;
    c.shadow_y1 = 400;
    return decode::render_plane(decode::default_sensor_geometry(), c);
  }();
  return s;
}

/// A frame without projector light (ambient only).
const std::vector<std::uint8_t>& dark_frame() {
  static const std::vector<std::uint8_t> dark(
      static_cast<std::size_t>(scene().width) * static_cast<std::size_t>(scene().height), 20);
  return dark;
}

/// One delivery: projector frame number f (-1: projector not running yet), camera id, stamp.
struct Delivery {
  std::int64_t f = 0;
  std::uint64_t id = 0;
  std::int64_t t_ns = 0;
};

/// A camera that sees projector frames from `first_f` on, id `first_id`, stamps f * period.
std::vector<Delivery> stream(std::int64_t first_f, std::int64_t count, std::uint64_t first_id = 1,
                             int id_bits = 16) {
  std::vector<Delivery> out;
  std::uint64_t id = first_id;
  for (std::int64_t i = 0; i < count; ++i) {
    out.push_back({first_f + i, id, (first_f + i) * kPeriodNs + 5'000'000});
    ++id;
    if (id_bits < 64 && id >= (std::uint64_t{1} << id_bits)) id = 1;  // GigE: 0 is skipped
  }
  return out;
}

void erase_f(std::vector<Delivery>& s, std::int64_t from_f, std::int64_t to_f) {
  std::erase_if(s, [&](const Delivery& d) { return d.f >= from_f && d.f < to_f; });
}

struct Outcome {
  SequencerStats stats;
  std::int64_t labelled = 0;
  std::int64_t mislabelled = 0;
  std::int64_t sequence_errors = 0;       ///< sequence advanced less than f
  std::int64_t sequence_regressions = 0;  ///< sequence did not advance
  std::int64_t first_labelled_f = -1;
  std::vector<std::int64_t> labelled_f;
};

/// Feeds the deliveries and checks every released label against the truth.
/// The sequencer over `deliveries`; from delivery `retune_at` on (if given) with `retuned`'s
/// thresholds (PatternSequencer::retune, the camera component's live parameters).
Outcome run(const std::vector<Delivery>& deliveries, SequencerConfig config = {},
            std::optional<std::size_t> retune_at = std::nullopt,
            const SequencerConfig& retuned = {}) {
  PatternSequencer sequencer(config);
  Outcome o;
  std::map<std::uint64_t, std::int64_t> f_of_token;
  std::optional<std::int64_t> last_sequence, last_f;
  const auto check = [&](const Released& r) {
    for (int i = 0; i < r.count; ++i) {
      const ReleasedFrame& rf = r.frames[static_cast<std::size_t>(i)];
      const std::int64_t f = f_of_token.at(rf.token);
      f_of_token.erase(rf.token);
      if (rf.reason != DropReason::kNone) continue;
      ++o.labelled;
      o.labelled_f.push_back(f);
      if (o.first_labelled_f < 0) o.first_labelled_f = f;
      const int slot = static_cast<int>(f % kFramesPerCycle);
      const bool ok = f >= 0 && rf.label.bit_index == slot / 2 &&
                      (rf.label.polarity == Polarity::kPositive) == (slot % 2 == 0);
      if (!ok) ++o.mislabelled;
      const std::int64_t sequence = rf.label.cycle * kFramesPerCycle + 2 * rf.label.bit_index +
                                    (rf.label.polarity == Polarity::kNegative ? 1 : 0);
      if (last_sequence && sequence - *last_sequence < f - *last_f) ++o.sequence_errors;
      if (last_sequence && sequence <= *last_sequence) ++o.sequence_regressions;
      last_sequence = sequence;
      last_f = f;
    }
  };
  std::uint64_t token = 0;
  for (const Delivery& d : deliveries) {
    if (retune_at && static_cast<std::size_t>(&d - deliveries.data()) == *retune_at) {
      sequencer.retune(retuned);
    }
    CameraFrame frame;
    frame.frame_id = d.id;
    frame.timestamp_ns = d.t_ns;
    const auto& pixels =
        d.f < 0 ? dark_frame() : scene().frames[static_cast<std::size_t>(d.f % kFramesPerCycle)];
    frame.image = {pixels.data(), scene().width, scene().height, 0};
    frame.token = ++token;
    f_of_token[frame.token] = d.f;
    check(sequencer.push(frame));
  }
  check(sequencer.flush());
  EXPECT_TRUE(f_of_token.empty()) << f_of_token.size() << " frames never released";
  o.stats = sequencer.stats();
  return o;
}

/// No labelled frame shows another pattern than its label, and the sequence advanced with the
/// projector's.
void expect_true_labels(const Outcome& o) {
  EXPECT_EQ(o.mislabelled, 0);
  EXPECT_EQ(o.sequence_errors, 0);
}

TEST(PatternSequencer, CleanStreamLocksWithinThreeCyclesAndLabelsEverythingAfter) {
  const Outcome o = run(stream(0, 10 * kFramesPerCycle, 100));
  expect_true_labels(o);
  EXPECT_EQ(o.stats.locks, 1);
  EXPECT_EQ(o.stats.gaps, 0);
  // lock_cycles = 2 full cycles seen (+ the couple before them), then from the next cycle start.
  EXPECT_EQ(o.first_labelled_f % kFramesPerCycle, 0);
  EXPECT_LE(o.first_labelled_f, 3 * kFramesPerCycle);
  EXPECT_EQ(o.labelled, 10 * kFramesPerCycle - o.first_labelled_f);
}

TEST(PatternSequencer, CameraStartingMidCycleLocksAtTheNextCycleStart) {
  for (const std::int64_t start : {1, 7, 17}) {
    const Outcome o = run(stream(start, 8 * kFramesPerCycle));
    SCOPED_TRACE("start " + std::to_string(start));
    expect_true_labels(o);
    EXPECT_EQ(o.stats.locks, 1);
    EXPECT_EQ(o.first_labelled_f % kFramesPerCycle, 0);
  }
}

TEST(PatternSequencer, SingleDropIsBridgedAndCounted) {
  std::vector<Delivery> s = stream(0, 10 * kFramesPerCycle);
  erase_f(s, 5 * kFramesPerCycle + 7, 5 * kFramesPerCycle + 8);  // bit 3 negative
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.gaps, 1);
  EXPECT_EQ(o.stats.missing_ids, 1);
  EXPECT_EQ(o.stats.bridged_gaps, 1);
  EXPECT_EQ(o.stats.locks, 1);
  EXPECT_EQ(o.stats.dropped_unpaired, 1);  // bit 3's positive, alone
}

TEST(PatternSequencer, BurstDropIsBridgedWhenTimestampsAgree) {
  std::vector<Delivery> s = stream(0, 12 * kFramesPerCycle);
  erase_f(s, 5 * kFramesPerCycle + 3, 5 * kFramesPerCycle + 28);  // 25 frames
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.gaps, 1);
  EXPECT_EQ(o.stats.missing_ids, 25);
  EXPECT_EQ(o.stats.locks, 1);
  // Frames after the burst are labelled at once.
  EXPECT_TRUE(std::find(o.labelled_f.begin(), o.labelled_f.end(), 5 * kFramesPerCycle + 28) !=
              o.labelled_f.end());
}

TEST(PatternSequencer, BurstLongerThanTheBridgeRelocks) {
  std::vector<Delivery> s = stream(0, 30 * kFramesPerCycle);
  erase_f(s, 5 * kFramesPerCycle, 5 * kFramesPerCycle + 400);
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.gaps, 1);
  EXPECT_EQ(o.stats.lock_losses, 1);
  EXPECT_EQ(o.stats.locks, 2);
}

TEST(PatternSequencer, DuplicatedFrameIsDropped) {
  std::vector<Delivery> s = stream(0, 10 * kFramesPerCycle);
  const auto it = s.begin() + 6 * kFramesPerCycle + 4;
  s.insert(it + 1, *it);
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.duplicates, 1);
  EXPECT_EQ(o.stats.gaps, 0);
  EXPECT_EQ(o.stats.locks, 1);
}

TEST(PatternSequencer, LateFrameIsDroppedWithoutLosingTheLock) {
  // A frame the transport completed after its successor (packets resent) comes in late.
  std::vector<Delivery> s = stream(0, 10 * kFramesPerCycle);
  std::swap(s[6 * kFramesPerCycle + 4], s[6 * kFramesPerCycle + 5]);
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.late_frames, 1);
  EXPECT_EQ(o.stats.restarts, 0);
  EXPECT_EQ(o.stats.lock_losses, 0);
  EXPECT_EQ(o.stats.locks, 1);
}

TEST(PatternSequencer, FrameIdWrapIsContinuous) {
  // GigE Vision 16-bit block ids: ..., 65534, 65535, 1, 2, ... (0 is invalid).
  const Outcome o = run(stream(0, 10 * kFramesPerCycle, 65535 - 5 * kFramesPerCycle));
  expect_true_labels(o);
  EXPECT_EQ(o.stats.gaps, 0);
  EXPECT_EQ(o.stats.locks, 1);
  EXPECT_EQ(o.labelled, 10 * kFramesPerCycle - o.first_labelled_f);
  // A camera with 64-bit ids does not wrap there.
  const Outcome wide = run(stream(0, 6 * kFramesPerCycle, 65535 - 2 * kFramesPerCycle, 64),
                           SequencerConfig{.frame_id_bits = 64});
  EXPECT_EQ(wide.mislabelled, 0);
  EXPECT_EQ(wide.stats.gaps, 0);
}

TEST(PatternSequencer, CameraRestartedMidCycleRelocksWithoutMislabelling) {
  std::vector<Delivery> s = stream(0, 6 * kFramesPerCycle + 5, 400);
  // The camera restarts: ids from 1 again and its clock from 0; the projector went on.
  for (Delivery d : stream(6 * kFramesPerCycle + 40, 8 * kFramesPerCycle, 1)) {
    d.t_ns -= (6 * kFramesPerCycle + 40) * kPeriodNs;
    s.push_back(d);
  }
  const Outcome o = run(s);
  EXPECT_EQ(o.mislabelled, 0);
  // The restarted camera's clock cannot say how long it was away: the cycle number jumps by
  // relock_cycle_jump (and the frames seen), less than the projector's 5 cycles here, but
  // enough that the decoder holds no bit from before as recent.
  EXPECT_EQ(o.sequence_errors, 1);
  EXPECT_EQ(o.sequence_regressions, 0);
  EXPECT_EQ(o.stats.restarts, 1);
  EXPECT_EQ(o.stats.locks, 2);
  EXPECT_EQ(o.stats.lock_losses, 1);
}

TEST(PatternSequencer, ProjectorStartedLateIsWaitedFor) {
  std::vector<Delivery> s = stream(0, 12 * kFramesPerCycle);
  for (std::size_t i = 0; i < 50; ++i) s[i].f = -1;  // dark until the projector starts
  // The projector starts at its cycle start (frame 50 shows bit 0 positive).
  for (std::size_t i = 50; i < s.size(); ++i) s[i].f = static_cast<std::int64_t>(i) - 50;
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.locks, 1);
  EXPECT_GE(o.first_labelled_f, 0);
  EXPECT_GT(o.labelled, 6 * kFramesPerCycle);
}

TEST(PatternSequencer, MissedExposureShowsInTheTimestampAndDropsTheLock) {
  // The camera misses one trigger: its id goes on by one, its timestamp by two periods.
  std::vector<Delivery> s = stream(0, 12 * kFramesPerCycle);
  for (std::size_t i = 4 * kFramesPerCycle + 9; i < s.size(); ++i) {
    s[i].f += 1;
    s[i].t_ns += kPeriodNs;
  }
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.gaps, 1);
  EXPECT_EQ(o.stats.lock_losses, 1);
  EXPECT_EQ(o.stats.locks, 2);
}

TEST(PatternSequencer, SlipWithoutATraceIsCaughtByThePairStructure) {
  // One projector frame never reaches the camera and neither id nor timestamp shows it (a
  // camera that stamps on arrival): the pair that straddles the slip does not sum to the
  // lit scene, and nothing from it is labelled.
  std::vector<Delivery> s = stream(0, 12 * kFramesPerCycle);
  for (std::size_t i = 4 * kFramesPerCycle + 8; i < s.size(); ++i) s[i].f += 1;
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.verify_failures, 1);
  EXPECT_EQ(o.stats.locks, 2);
}

TEST(PatternSequencer, SlipRightAfterABridgedGapIsCaughtToo) {
  // Found by fuzz_pattern_sequencer: frames lost in transport (the ids skip as many), then a
  // slip without a trace. The first pair after the gap had no pair two frames back to be
  // compared with and was labelled unchecked; it is now checked against the last pair before
  // the gap.
  std::vector<Delivery> s = stream(0, 12 * kFramesPerCycle);
  erase_f(s, 4 * kFramesPerCycle + 2, 4 * kFramesPerCycle + 8);  // 6 frames, ids skip 6
  for (Delivery& d : s) {
    if (d.f >= 4 * kFramesPerCycle + 9) d.f += 1;  // the frame after the gap's first slipped
  }
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.bridged_gaps, 1);
  EXPECT_EQ(o.stats.verify_failures, 1);
  EXPECT_EQ(o.stats.locks, 2);
}

TEST(PatternSequencer, FramesBeforeTheLastRestartAreNeverTakenForLateFrames) {
  // Found by fuzz_pattern_sequencer: the camera restarts with ids from 8 (its clock as if from
  // id 1), locks, then restarts again from id 1 with the same clock origin. Ids 1..6 fit
  // places inside the first restart's advance, never ids of this stream: they were taken for
  // frames completed late, the lock stayed, and the next ids (41 on, continuing the first
  // numbering) were labelled 6 frames off: 3 whole pairs, which pair sums cannot see.
  const std::int64_t ms = 1'000'000;
  std::vector<Delivery> s = stream(0, 40);
  std::int64_t f = 40;
  for (std::uint64_t id = 8; id <= 40; ++id)
    s.push_back({f++, id, static_cast<std::int64_t>(id - 1) * ms});
  for (std::uint64_t id = 1; id <= 6; ++id)
    s.push_back({f++, id, static_cast<std::int64_t>(id - 1) * ms});
  for (std::uint64_t id = 41; id <= 41 + 8 * kFramesPerCycle; ++id) {
    s.push_back({f++, id, static_cast<std::int64_t>(id - 1) * ms});
  }
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.late_frames, 0);
  EXPECT_GE(o.stats.restarts, 2);
  EXPECT_GT(o.labelled, 2 * kFramesPerCycle);
}

TEST(PatternSequencer, RestartSoonAfterStartIsNotTakenForLateFrames) {
  // Found by fuzz_pattern_sequencer: the camera restarts 100 frames after it started, its ids
  // from 1 and its clock from the same origin again. The new ids looked like frames completed
  // late (older ids, timestamps as much older) and were dropped until they passed the old
  // ones; from there they continued the old ids, 100 frames off, and the lock stayed.
  std::vector<Delivery> s = stream(0, 100);
  for (const Delivery& d : stream(0, 10 * kFramesPerCycle)) s.push_back({d.f + 100, d.id, d.t_ns});
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.late_frames, 0);
  EXPECT_GE(o.stats.restarts, 1);
  EXPECT_GT(o.labelled, 0);
}

TEST(PatternSequencer, SlipAfterGapsLongerThanTheBridgeIsNotLabelled) {
  // Found by fuzz_pattern_sequencer: gaps of 16 frames, each bridged, one after another for
  // longer than the bridge (180 frames), so that no pair was checked meanwhile, then a slip:
  // the first pair had nothing within reach to be compared with and was labelled. It is now
  // not labelled and the lock is dropped: its sum is no reference (a misaligned couple after a
  // slip would match the next misaligned couple, found by the fuzzer too); hunting relocks.
  std::vector<Delivery> s = stream(0, 30 * kFramesPerCycle);
  const std::int64_t from = 4 * kFramesPerCycle, to = from + 17 * 12;
  std::erase_if(
      s, [&](const Delivery& d) { return d.f >= from && d.f < to && (d.f - from) % 17 != 0; });
  for (Delivery& d : s) {
    if (d.f >= to + 1) d.f += 1;  // the slip
  }
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_GE(o.stats.unverified_pairs, 1);
  EXPECT_GE(o.stats.lock_losses, 1);
  EXPECT_EQ(o.stats.locks, o.stats.lock_losses + 1) << "relocked after the slip";
  EXPECT_GT(o.labelled_f.back(), to + 6 * kFramesPerCycle) << "labelling resumed";
}

TEST(PatternSequencer, ClockJumpingAcrossTheRangeIsARestartNotAnOverflow) {
  // Camera timestamps are outside input: a jump from near INT64_MIN to near INT64_MAX (the
  // difference does not fit in 64 bits) was signed overflow (undefined behaviour, found by
  // fuzz_pattern_sequencer under UBSan); it is a restart: lock lost, later frames true.
  std::vector<Delivery> s = stream(0, 10 * kFramesPerCycle);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s[i].t_ns += i < 4 * kFramesPerCycle ? std::numeric_limits<std::int64_t>::min() / 2 * 2
                                         : std::numeric_limits<std::int64_t>::max() / 2;
  }
  const Outcome o = run(s);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.restarts, 1);
  EXPECT_EQ(o.stats.lock_losses, 1);
  EXPECT_GT(std::count_if(o.labelled_f.begin(), o.labelled_f.end(),
                          [](std::int64_t f) { return f >= 4 * kFramesPerCycle; }),
            0);  // labelling resumed after the jump
}

TEST(PatternSequencer, TimestampJitterWithinToleranceIsNoGap) {
  std::vector<Delivery> s = stream(0, 8 * kFramesPerCycle);
  for (std::size_t i = 0; i < s.size(); ++i) s[i].t_ns += (i % 3 == 0 ? 1 : -1) * kPeriodNs / 5;
  const Outcome o = run(s);
  EXPECT_EQ(o.mislabelled, 0);
  EXPECT_EQ(o.stats.gaps, 0);
  EXPECT_EQ(o.stats.locks, 1);
}

TEST(PatternSequencer, DarkSceneNeverLocks) {
  std::vector<Delivery> s = stream(0, 6 * kFramesPerCycle);
  for (Delivery& d : s) d.f = -1;
  const Outcome o = run(s);
  EXPECT_EQ(o.labelled, 0);
  EXPECT_EQ(o.stats.locks, 0);
  EXPECT_EQ(o.stats.dropped_not_locked, 6 * kFramesPerCycle);
}

TEST(PatternSequencer, ThresholdRetunedWhileRunningTakesEffectFromTheNextFrame) {
  // Psi 255 decides no bit (Eq. 2): the structure cannot be seen and nothing locks. Retuned
  // to 10 after 4 cycles, the sequencer locks as on a clean stream from there.
  SequencerConfig blind;
  blind.threshold_psi = 255;
  const SequencerConfig normal;
  const Outcome o = run(stream(0, 10 * kFramesPerCycle, 100), blind, 4 * kFramesPerCycle, normal);
  expect_true_labels(o);
  EXPECT_EQ(o.stats.locks, 1);
  EXPECT_GE(o.first_labelled_f, 4 * kFramesPerCycle);
  EXPECT_LE(o.first_labelled_f, 7 * kFramesPerCycle);
  EXPECT_EQ(o.labelled, 10 * kFramesPerCycle - o.first_labelled_f);
  const Outcome never = run(stream(0, 10 * kFramesPerCycle, 100), blind);
  EXPECT_EQ(never.stats.locks, 0);
}

TEST(PatternSequencer, LabelledFramesDecodeToThePlane) {
  // The decoder fed only what the sequencer labels sees the plane's true depth.
  std::vector<Delivery> s = stream(3, 6 * kFramesPerCycle);
  erase_f(s, 4 * kFramesPerCycle + 2, 4 * kFramesPerCycle + 3);
  PatternSequencer sequencer(SequencerConfig{});
  decode::RollingDecoder decoder(decode::DecoderConfig{});
  std::map<std::uint64_t, std::int64_t> f_of_token;
  int maps = 0;
  double worst_error_m = 0;
  const auto feed = [&](const Released& r) {
    for (int i = 0; i < r.count; ++i) {
      const ReleasedFrame& rf = r.frames[static_cast<std::size_t>(i)];
      const std::int64_t f = f_of_token.at(rf.token);
      if (rf.reason != DropReason::kNone) continue;
      decode::PatternFrame frame;
      const auto& pixels = scene().frames[static_cast<std::size_t>(f % kFramesPerCycle)];
      frame.image = {pixels.data(), scene().width, scene().height, 0};
      frame.bit_index = rf.label.bit_index;
      frame.polarity = rf.label.polarity;
      frame.cycle = rf.label.cycle;
      const decode::DecodeResult result = decoder.push_frame(frame);
      if (!result.depth_updated) continue;
      ++maps;
      for (std::size_t p = 0; p < result.depth_m.size(); ++p) {
        if (!scene().lit[p] || scene().shadowed[p] || std::isnan(result.depth_m[p])) continue;
        worst_error_m =
            std::max(worst_error_m, std::abs(double{result.depth_m[p]} - scene().true_depth_m[p]));
      }
    }
  };
  std::uint64_t token = 0;
  for (const Delivery& d : s) {
    const auto& pixels = scene().frames[static_cast<std::size_t>(d.f % kFramesPerCycle)];
    CameraFrame frame{d.id, d.t_ns, {pixels.data(), scene().width, scene().height, 0}, ++token};
    f_of_token[frame.token] = d.f;
    feed(sequencer.push(frame));
  }
  EXPECT_GT(maps, 20);
  EXPECT_LT(worst_error_m, 0.05);  // a wrong bit would put a pixel codes (centimetres) away
}

}  // namespace
}  // namespace avs::camera
