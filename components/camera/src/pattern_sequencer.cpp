// PatternSequencer: frame ids and timestamps -> (cycle, bit, polarity), see the header.
#include "avs/camera/pattern_sequencer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace avs::camera {

using decode::Polarity;

std::string_view to_string(DropReason reason) {
  switch (reason) {
    case DropReason::kNone:
      return "labelled";
    case DropReason::kNotLocked:
      return "not locked";
    case DropReason::kDuplicate:
      return "duplicate frame id";
    case DropReason::kLate:
      return "late frame (older id)";
    case DropReason::kUnpaired:
      return "pair partner lost";
    case DropReason::kVerifyFailed:
      return "pair structure mismatch";
    case DropReason::kUnverified:
      return "pair not checkable";
    case DropReason::kFlushed:
      return "flushed";
  }
  return "?";
}

PatternSequencer::PatternSequencer(SequencerConfig config)
    : config_(config), frames_per_cycle_(2 * static_cast<std::int64_t>(config.bit_count)) {
  if (config_.bit_count < 2 || config_.bit_count > 15) {
    throw std::invalid_argument("PatternSequencer: bit_count " + std::to_string(config_.bit_count) +
                                ", expected 2..15");
  }
  if (!(config_.frame_period_s > 0)) {
    throw std::invalid_argument("PatternSequencer: frame_period_s must be > 0");
  }
  if (config_.frame_id_bits < 2 || config_.frame_id_bits > 64) {
    throw std::invalid_argument("PatternSequencer: frame_id_bits " +
                                std::to_string(config_.frame_id_bits) + ", expected 2..64");
  }
  if (config_.lock_cycles < 1) throw std::invalid_argument("PatternSequencer: lock_cycles < 1");
  if (config_.max_bridged_gap_frames < 0 || config_.max_bridged_gap_frames > 1'000'000) {
    throw std::invalid_argument("PatternSequencer: max_bridged_gap_frames " +
                                std::to_string(config_.max_bridged_gap_frames) +
                                ", expected 0..1000000");
  }
  received_.assign(static_cast<std::size_t>(config_.max_bridged_gap_frames) + 1, -1);
  if (config_.relock_cycle_jump < 2) {
    throw std::invalid_argument("PatternSequencer: relock_cycle_jump < 2");
  }
}

std::int64_t PatternSequencer::id_step(std::uint64_t id) const {
  if (config_.frame_id_bits >= 64) return static_cast<std::int64_t>(id - last_id_);
  const std::uint64_t modulus =
      (std::uint64_t{1} << config_.frame_id_bits) - (config_.frame_id_zero_skipped ? 1 : 0);
  const std::uint64_t offset = config_.frame_id_zero_skipped ? 1 : 0;
  const std::uint64_t a = (id - offset) % modulus;
  const std::uint64_t b = (last_id_ - offset) % modulus;
  const std::uint64_t forward = (a + modulus - b) % modulus;
  return forward > modulus / 2
             ? static_cast<std::int64_t>(forward) - static_cast<std::int64_t>(modulus)
             : static_cast<std::int64_t>(forward);
}

Released PatternSequencer::push(const CameraFrame& frame) {
  ++stats_.frames;
  Released out;
  if (!have_last_) {
    have_last_ = true;
    last_id_ = frame.frame_id;
    last_timestamp_ns_ = frame.timestamp_ns;
    position_ = 0;
    stream_start_position_ = 0;
    note_received();
    hunt(frame, false, out);
    return out;
  }
  const std::int64_t step = id_step(frame.frame_id);
  if (step == 0) {
    ++stats_.duplicates;
    out.add(release(frame, DropReason::kDuplicate));
    return out;
  }
  // A camera's clock is outside input: one that jumps across the int64 range is a restart,
  // never an overflow.
  std::int64_t dt_ns = 0;
  const bool clock_jumped = __builtin_sub_overflow(frame.timestamp_ns, last_timestamp_ns_, &dt_ns);
  const double periods = static_cast<double>(dt_ns) * 1e-9 / config_.frame_period_s;
  const bool consistent = !clock_jumped && std::abs(periods - static_cast<double>(step)) <=
                                               config_.gap_tolerance_periods;
  // A frame completed after newer ones has an id that was missing. An id received before,
  // with a timestamp that fits its old place, is a camera that restarted its ids and its clock
  // soon after it started (found by fuzz_pattern_sequencer: taken as late frames, the new ids
  // then continued the old ones, shifted by a restart's worth of exposures): a restart below.
  // Its place must also lie after the last discontinuity: a place before it (inside the
  // advance past a restart or an unbridged gap) was never an id of this stream. A camera that
  // restarted twice, the second time with ids and a clock that fitted places inside the first
  // restart's advance, was taken for late frames, the lock kept, and its next frames continued
  // the old ids 23 exposures off: labelled a whole pair off, which pair sums cannot see
  // (fuzz_pattern_sequencer, 2026-12-06).
  if (step < 0 && consistent && -step <= config_.max_bridged_gap_frames &&
      position_ + step >= stream_start_position_ && !was_received(position_ + step)) {
    ++stats_.late_frames;  // completed after newer frames: nothing to relabel
    mark_received(position_ + step);
    out.add(release(frame, DropReason::kLate));
    return out;
  }
  last_id_ = frame.frame_id;
  last_timestamp_ns_ = frame.timestamp_ns;
  if (step < 0 || dt_ns <= 0 || clock_jumped) {  // ids or clock went back: the camera restarted
    ++stats_.restarts;
    ++stats_.gaps;
    // Not adjacent to anything before (no pair across a restart), and no earlier id's place
    // is taken for one of the new ids.
    position_ += config_.max_bridged_gap_frames + 2;
    stream_start_position_ = position_;
    note_received();
    lose_lock(out);
    hunt(frame, false, out);
    return out;
  }
  if (step > 1) {  // saturating: ids of any width may jump by up to half their range
    stats_.missing_ids = step - 1 > std::numeric_limits<std::int64_t>::max() - stats_.missing_ids
                             ? std::numeric_limits<std::int64_t>::max()
                             : stats_.missing_ids + (step - 1);
  }
  if (step != 1 || !consistent) ++stats_.gaps;
  // Past a gap that cannot be bridged only "not adjacent" matters (no pair across it): a
  // bounded advance keeps position_ from overflowing on ids or clocks that jump far.
  const std::int64_t bridge = config_.max_bridged_gap_frames;
  if (consistent && step <= bridge) {
    position_ += step;
  } else {
    position_ += bridge + 2;
    stream_start_position_ = position_;  // no late frame from before an unbridged gap
  }
  note_received();
  if (locked_) {
    if (consistent && step <= config_.max_bridged_gap_frames) {
      if (step > 1) ++stats_.bridged_gaps;
      locked_push(frame, out);
      return out;
    }
    lose_lock(out);
  }
  hunt(frame, consistent && step == 1, out);
  return out;
}

bool PatternSequencer::was_received(std::int64_t position) const {
  if (position < 0) return false;  // before the first frame seen
  return received_[static_cast<std::size_t>(position) % received_.size()] == position;
}

void PatternSequencer::mark_received(std::int64_t position) {
  if (position >= 0) received_[static_cast<std::size_t>(position) % received_.size()] = position;
}

void PatternSequencer::retune(const SequencerConfig& next) {
  config_.threshold_psi = next.threshold_psi;
  config_.pair_sum_match_max = next.pair_sum_match_max;
  config_.pair_sum_mismatch_min = next.pair_sum_mismatch_min;
  config_.verify_pairs = next.verify_pairs;
}

Released PatternSequencer::flush() {
  Released out;
  if (held_) {
    out.add(release(*held_, DropReason::kFlushed));
    held_.reset();
  }
  return out;
}

void PatternSequencer::lose_lock(Released& out) {
  if (locked_) ++stats_.lock_losses;
  locked_ = false;
  run_.clear();
  sum_position_ = {-1, -1};
  if (held_) {
    out.add(release(*held_, DropReason::kNotLocked));
    held_.reset();
  }
}

void PatternSequencer::hunt(const CameraFrame& frame, bool continuous, Released& out) {
  if (!continuous) lose_lock(out);
  Structure s;
  if (held_ && held_position_ == position_ - 1) {
    s.sum_difference = couple_sum_difference(frame, 2, 2);
    s.density = couple_density(frame);
  }
  run_.push_back(s);
  const std::size_t keep =
      2 * static_cast<std::size_t>(config_.lock_cycles * config_.bit_count) + 2;
  if (run_.size() > keep) run_.erase(run_.begin(), run_.end() - static_cast<std::ptrdiff_t>(keep));
  if (held_) {
    out.add(release(*held_, DropReason::kNotLocked));
    held_.reset();
  }
  if (!structure_locks()) {
    held_ = frame;
    held_position_ = position_;
    return;
  }
  // This frame is the negative of bit n-1: the next one starts a cycle. After an earlier
  // lock the new cycle number leaves at least one whole cycle unnumbered, more when more time
  // passed, so the decoder never counts a pre-gap bit as recent.
  // Elapsed time: the camera clock's, at least one period per frame seen since (a restarted
  // camera's clock says nothing).
  std::int64_t next_cycle = 0;
  if (last_emitted_cycle_ >= 0) {
    const double cycle_s = config_.frame_period_s * static_cast<double>(frames_per_cycle_);
    const double elapsed_s = std::max(
        (static_cast<double>(frame.timestamp_ns) -
         static_cast<double>(last_emitted_timestamp_ns_)) *
            1e-9,
        static_cast<double>(stats_.frames - last_emitted_frames_) * config_.frame_period_s);
    next_cycle =
        last_emitted_cycle_ +
        std::max<std::int64_t>(config_.relock_cycle_jump,
                               static_cast<std::int64_t>(std::ceil(elapsed_s / cycle_s)) + 1);
  }
  locked_ = true;
  ++stats_.locks;
  origin_sequence_ = next_cycle * frames_per_cycle_ - 1;
  origin_position_ = position_;
  run_.clear();
  out.add(release(frame, DropReason::kNotLocked));
}

bool PatternSequencer::structure_locks() const {
  const int n = config_.bit_count;
  const int pairs = config_.lock_cycles * n;
  if (run_.size() < 2 * static_cast<std::size_t>(pairs) + 2) return false;
  const std::size_t last = run_.size() - 1;
  int mismatches = 0;
  std::vector<double>& density = density_scratch_;  // no allocation per frame once sized
  density.assign(static_cast<std::size_t>(pairs), 0.0);
  for (int j = 0; j < pairs; ++j) {
    const std::size_t end = last - 2 * static_cast<std::size_t>(pairs - 1 - j);
    const Structure& pair = run_[end];
    if (pair.sum_difference < 0 || pair.sum_difference > config_.pair_sum_match_max) return false;
    if (pair.density < 0) return false;
    density[static_cast<std::size_t>(j)] = pair.density;
    const Structure& couple = run_[end - 1];  // the previous negative with this positive
    if (couple.sum_difference >= 0 && couple.sum_difference <= config_.pair_sum_match_max) {
      return false;  // a misaligned couple that looks like a pair: parity not certain
    }
    if (couple.sum_difference >= config_.pair_sum_mismatch_min) ++mismatches;
  }
  if (2 * mismatches < pairs) return false;
  // Each cycle of the window ends with its finest pattern: most transitions by a margin.
  for (int g = 0; g < config_.lock_cycles; ++g) {
    const double lsb = density[static_cast<std::size_t>(g * n + n - 1)];
    if (lsb < 0.01) return false;
    for (int k = 0; k < n - 1; ++k) {
      if (lsb < config_.lsb_density_ratio * density[static_cast<std::size_t>(g * n + k)]) {
        return false;
      }
    }
  }
  return true;
}

double PatternSequencer::couple_sum_difference(const CameraFrame& frame, std::int64_t distance,
                                               std::int64_t max_distance) {
  const decode::ImageView8& a = held_->image;
  const decode::ImageView8& b = frame.image;
  if (a.width != b.width || a.height != b.height || a.data == nullptr || b.data == nullptr) {
    return -1;
  }
  const std::size_t pixels = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  scratch_.resize(pixels);
  const std::ptrdiff_t stride_a = a.stride_bytes > 0 ? a.stride_bytes : a.width;
  const std::ptrdiff_t stride_b = b.stride_bytes > 0 ? b.stride_bytes : b.width;
  for (int y = 0; y < a.height; ++y) {
    const std::uint8_t* ra = a.data + y * stride_a;
    const std::uint8_t* rb = b.data + y * stride_b;
    std::uint16_t* rs =
        scratch_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(a.width);
    for (int x = 0; x < a.width; ++x) rs[x] = static_cast<std::uint16_t>(ra[x] + rb[x]);
  }
  const std::size_t slot = static_cast<std::size_t>(position_ & 1);
  double result = -1;
  const std::int64_t back = position_ - sum_position_[slot];
  if (sum_position_[slot] >= 0 && back >= distance && back <= max_distance &&
      sums_[slot].size() == pixels) {
    const std::uint16_t* old = sums_[slot].data();
    const std::uint16_t* now = scratch_.data();
    const int lit_min = config_.lit_sum_min;
    std::int64_t lit = 0, difference = 0, total = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (now[i] > lit_min || old[i] > lit_min) {
        ++lit;
        difference += std::abs(static_cast<int>(now[i]) - static_cast<int>(old[i]));
        total += now[i] + old[i];
      }
    }
    if (static_cast<double>(lit) >= config_.min_lit_fraction * static_cast<double>(pixels) &&
        total > 0) {
      result = static_cast<double>(difference) / (0.5 * static_cast<double>(total));
    }
  }
  std::swap(scratch_, sums_[slot]);
  sum_position_[slot] = position_;
  return result;
}

double PatternSequencer::couple_density(const CameraFrame& frame) const {
  const decode::ImageView8& p = held_->image;
  const decode::ImageView8& q = frame.image;
  if (p.width != q.width || p.height != q.height || p.data == nullptr || q.data == nullptr) {
    return -1;
  }
  const std::ptrdiff_t stride_p = p.stride_bytes > 0 ? p.stride_bytes : p.width;
  const std::ptrdiff_t stride_q = q.stride_bytes > 0 ? q.stride_bytes : q.width;
  const int psi = config_.threshold_psi;
  // Eq. 2 per pixel: 1, 0 or undecided (-1); transitions between decided 4-neighbours.
  const auto bit = [&](int x, int y) {
    const int v = p.data[y * stride_p + x] - q.data[y * stride_q + x];
    return v > psi ? 1 : (v < -psi ? 0 : -1);
  };
  std::int64_t neighbours = 0, transitions = 0;
  std::vector<int>& previous_row = row_scratch_;  // no allocation per frame once sized
  previous_row.assign(static_cast<std::size_t>(p.width), -1);
  for (int y = 0; y < p.height; ++y) {
    int left = -1;
    for (int x = 0; x < p.width; ++x) {
      const int b = bit(x, y);
      if (b >= 0) {
        const int up = previous_row[static_cast<std::size_t>(x)];
        if (left >= 0) {
          ++neighbours;
          transitions += b != left;
        }
        if (up >= 0) {
          ++neighbours;
          transitions += b != up;
        }
      }
      previous_row[static_cast<std::size_t>(x)] = b;
      left = b;
    }
  }
  const double pixels = static_cast<double>(p.width) * static_cast<double>(p.height);
  if (static_cast<double>(neighbours) < config_.min_lit_fraction * pixels) return -1;
  return static_cast<double>(transitions) / static_cast<double>(neighbours);
}

void PatternSequencer::locked_push(const CameraFrame& frame, Released& out) {
  if (held_ && held_position_ != position_ - 1) {  // its negative was lost in a bridged gap
    out.add(release(*held_, DropReason::kUnpaired));
    held_.reset();
  }
  const std::int64_t sequence = origin_sequence_ + (position_ - origin_position_);
  const FrameLabel label = label_of(sequence);
  if (label.polarity == Polarity::kPositive) {
    if (held_) {  // cannot happen: a held frame is a positive one frame back
      out.add(release(*held_, DropReason::kUnpaired));
      held_.reset();
    }
    held_ = frame;
    held_position_ = position_;
    // Its sum with the negative is compared with the previous pair's (two frames back).
    return;
  }
  if (!held_) {
    out.add(release(frame, DropReason::kUnpaired));
    return;
  }
  // Against the previous pair, or after a bridged gap the last pair before it (same parity
  // slot): a pair after a gap released unverified let a camera that also slipped an exposure
  // there be mislabelled (found by fuzz_pattern_sequencer). Across a long gap a moving scene
  // may fail the check: that drops the lock (frames lost), never a label.
  const double difference =
      config_.verify_pairs
          ? couple_sum_difference(frame, 2,
                                  2 + static_cast<std::int64_t>(config_.max_bridged_gap_frames))
          : -1;
  if (config_.verify_pairs && difference < 0) {
    // Nothing to check it against (every pair since the last checked one lost in gaps for
    // longer than the bridge, found by fuzz_pattern_sequencer with a slip after them; or too
    // few lit pixels): not labelled, and the lock is dropped. Its sum must not become the
    // reference for the next pair: a camera that slipped an exposure inside those gaps makes
    // it a misaligned couple, and the next misaligned couple matched it and was labelled one
    // exposure off (fuzz_pattern_sequencer, 2026-12-06: 8 gaps of 16 frames after a slip).
    // Hunting finds the structure again from the images.
    ++stats_.unverified_pairs;
    out.add(release(*held_, DropReason::kUnverified));
    held_.reset();
    out.add(release(frame, DropReason::kUnverified));
    lose_lock(out);
    return;
  }
  if (difference > config_.pair_sum_match_max) {
    ++stats_.verify_failures;
    out.add(release(*held_, DropReason::kVerifyFailed));
    held_.reset();
    out.add(release(frame, DropReason::kVerifyFailed));
    lose_lock(out);
    return;
  }
  out.add(release(*held_, DropReason::kNone, label_of(sequence - 1)));
  held_.reset();
  out.add(release(frame, DropReason::kNone, label));
  last_emitted_cycle_ = label.cycle;
  last_emitted_timestamp_ns_ = frame.timestamp_ns;
  last_emitted_frames_ = stats_.frames;
}

ReleasedFrame PatternSequencer::release(const CameraFrame& f, DropReason reason, FrameLabel label) {
  switch (reason) {
    case DropReason::kNone:
      ++stats_.labelled;
      break;
    case DropReason::kNotLocked:
    case DropReason::kFlushed:
      ++stats_.dropped_not_locked;
      break;
    case DropReason::kUnpaired:
      ++stats_.dropped_unpaired;
      break;
    case DropReason::kDuplicate:
    case DropReason::kLate:
    case DropReason::kVerifyFailed:
    case DropReason::kUnverified:
      break;  // counted (per pair) where they are detected
  }
  return {f.token, f.frame_id, reason, label};
}

FrameLabel PatternSequencer::label_of(std::int64_t sequence) const {
  const std::int64_t slot = sequence % frames_per_cycle_;
  FrameLabel label;
  label.cycle = sequence / frames_per_cycle_;
  label.bit_index = static_cast<int>(slot / 2);
  label.polarity = slot % 2 == 0 ? Polarity::kPositive : Polarity::kNegative;
  return label;
}

}  // namespace avs::camera
