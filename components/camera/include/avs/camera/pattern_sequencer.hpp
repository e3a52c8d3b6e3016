// Which pattern is this frame? A real camera delivers images with a frame id and a timestamp,
// not bit indices. The PatternSequencer labels each frame with (cycle, bit, polarity) of the
// projection order of section 4.1 (bit 0 positive, bit 0 negative, ..., bit n-1 negative: 2n
// frames per cycle, as `avs patterns` exports and the simulator renders) and NEVER mislabels:
//
//   * Hunting (not locked): every frame is dropped. The sequence's own structure tells where a
//     cycle starts. Pairs: a positive and its negative light complementary pixels, so the sum
//     of a true pair is the fully lit scene, the same for every pair, while the sums of
//     misaligned couples (a negative and the next bit's positive) differ from one another.
//     Bits: the finest pattern (bit n-1, the LSB of Eq. 1) has the most stripe transitions,
//     about twice the next finest, so the pair with the most transitions ends a cycle. Lock
//     when `lock_cycles` consecutive cycles of continuous frames all show both.
//   * Locked: labels follow from frame ids (the camera counts exposures, one per projector
//     trigger). A forward id gap whose timestamp step agrees (within gap_tolerance_periods)
//     is bridged and counted; any other discontinuity (timestamp step > 1.5 periods for one
//     id, ids going back or restarting, steps longer than max_bridged_gap_frames) drops the
//     lock. A duplicated id is dropped, and so is a late one (an id at most
//     max_bridged_gap_frames older than the last with a timestamp as much older: a frame the
//     transport completed after newer ones; an older id received before is a restart). A
//     positive is held until its negative: the pair is
//     released only when its sum matches the previous pair's (the structure above; a pair
//     with nothing to compare with is not labelled, its sum becomes the reference), so a
//     camera that slipped one exposure without a trace in its ids is caught before a frame
//     of it is labelled (also across a bridged gap: the first pair after it is checked against
//     the last pair before it). Sums cannot see a shift by a whole pair (two slips with no
//     checked pair between them): a true pair of another bit has the same sum.
//
// Core, no I/O: the caller owns the images and keeps a frame's image valid until the
// sequencer releases the frame (at most one frame is held between calls).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "avs/decode/patterns.hpp"
#include "avs/decode/rolling_decoder.hpp"

namespace avs::camera {

struct SequencerConfig {
  int bit_count = 9;                  ///< n (section 4: 9); 2n frames per cycle
  double frame_period_s = 0.001;      ///< projector pattern period (section 3.1: 1000 fps)
  int frame_id_bits = 16;             ///< GigE Vision block ids: 16 bits; 64: no wrap
  bool frame_id_zero_skipped = true;  ///< GigE Vision: id 0 is invalid, 65535 -> 1
  /// A step of k ids must come with a timestamp step within k +- this many periods.
  double gap_tolerance_periods = 0.5;
  /// Longest forward id gap bridged while locked (longer: lock lost).
  int max_bridged_gap_frames = 180;
  int lock_cycles = 2;     ///< consecutive cycles that must show the structure before locking
  int threshold_psi = 10;  ///< Eq. 2: |I_p - I_n| above this decides a bit (8-bit units)
  /// Pair sums: mean |S_pair - S_previous_pair| / mean S over lit pixels at most this for a
  /// true pair, at least pair_sum_mismatch_min for misaligned couples.
  double pair_sum_match_max = 0.12;
  double pair_sum_mismatch_min = 0.2;
  /// Pixels whose pair sum exceeds this count as lit; fewer lit than min_lit_fraction of the
  /// image: the structure cannot be seen (dark scene, projector off).
  int lit_sum_min = 40;
  double min_lit_fraction = 0.02;
  /// The LSB pair's stripe-transition density must be at least this times any other pair's.
  double lsb_density_ratio = 1.4;
  bool verify_pairs = true;  ///< check every locked pair's sum before releasing it
  /// After a lock is lost, the cycle number jumps by at least this much (more when the camera
  /// clock or the frames seen say more time passed), so that no bit from before the gap is
  /// younger than 2n pairs for the decoder (max_bit_age_pairs <= 2n never reuses one).
  int relock_cycle_jump = 3;
};

/// One camera frame. `token` is the caller's handle, returned when the frame is released.
struct CameraFrame {
  std::uint64_t frame_id = 0;
  std::int64_t timestamp_ns = 0;
  decode::ImageView8 image;
  std::uint64_t token = 0;
};

struct FrameLabel {
  int bit_index = 0;
  decode::Polarity polarity = decode::Polarity::kPositive;
  std::int64_t cycle = 0;
};

enum class DropReason : std::uint8_t {
  kNone = 0,      ///< labelled
  kNotLocked,     ///< hunting for the cycle start
  kDuplicate,     ///< same frame id again
  kLate,          ///< an older id than the last, its timestamp as much older (completed late)
  kUnpaired,      ///< its pair partner was lost (a lone frame cannot be verified or decoded)
  kVerifyFailed,  ///< the pair's structure did not match: lock dropped
  kUnverified,    ///< no earlier pair to check the pair against (long gaps, dark): not
                  ///< labelled, and the lock is dropped (hunting again)
  kFlushed,       ///< still held at flush()
};

std::string_view to_string(DropReason reason);

/// A frame the sequencer is done with: labelled (reason kNone) or dropped.
struct ReleasedFrame {
  std::uint64_t token = 0;
  std::uint64_t frame_id = 0;
  DropReason reason = DropReason::kNone;
  FrameLabel label;  ///< valid when reason == kNone
};

/// Up to two frames released by one call, in frame order (a held positive, then its negative).
struct Released {
  std::array<ReleasedFrame, 2> frames;
  int count = 0;
  void add(const ReleasedFrame& f) { frames[static_cast<std::size_t>(count++)] = f; }
};

struct SequencerStats {
  std::int64_t frames = 0;    ///< pushed
  std::int64_t labelled = 0;  ///< released with a label
  std::int64_t dropped_not_locked = 0;
  std::int64_t duplicates = 0;
  std::int64_t late_frames = 0;  ///< older ids arriving after newer ones; dropped
  std::int64_t dropped_unpaired = 0;
  std::int64_t verify_failures = 0;   ///< pairs whose structure did not match (lock dropped)
  std::int64_t unverified_pairs = 0;  ///< pairs with nothing to check them against: dropped,
                                      ///< and the lock with them
  std::int64_t missing_ids = 0;       ///< ids skipped by forward gaps
  std::int64_t gaps = 0;          ///< discontinuities of any kind (id skips, time steps, restarts)
  std::int64_t bridged_gaps = 0;  ///< gaps crossed while staying locked
  std::int64_t restarts = 0;      ///< ids or timestamps going back
  std::int64_t locks = 0;         ///< times the lock was acquired
  std::int64_t lock_losses = 0;
};

class PatternSequencer {
 public:
  explicit PatternSequencer(SequencerConfig config);

  /// Takes one frame; returns the frames released by it (this one, the held one, both or none:
  /// a frame not released is held, its image must stay valid until it is).
  Released push(const CameraFrame& frame);
  /// Releases the held frame, if any, as dropped (end of stream).
  Released flush();
  /// Takes the thresholds of `next` (threshold_psi, pair_sum_match_max, pair_sum_mismatch_min,
  /// verify_pairs: the camera component's live parameters) from the next frame on; the lock,
  /// the ids and the frame held stay. The structure settings (bits, ids, periods) stay too.
  void retune(const SequencerConfig& next);

  bool locked() const { return locked_; }
  const SequencerStats& stats() const { return stats_; }
  const SequencerConfig& config() const { return config_; }

 private:
  struct Structure {             ///< what one frame showed with its predecessor (hunting)
    double sum_difference = -1;  ///< vs the couple two frames back; < 0: not measurable
    double density = -1;         ///< stripe transitions of (previous, this) as a pair
  };

  std::int64_t id_step(std::uint64_t id) const;
  /// Whether a frame was received at `position` (within the last max_bridged_gap_frames).
  bool was_received(std::int64_t position) const;
  void mark_received(std::int64_t position);
  void note_received() { mark_received(position_); }
  void lose_lock(Released& out);
  void hunt(const CameraFrame& frame, bool continuous, Released& out);
  void locked_push(const CameraFrame& frame, Released& out);
  bool structure_locks() const;
  /// Mean |S - S_stored| / mean S over lit pixels of the couple (held, frame), storing S;
  /// -1 when too few pixels are lit or the stored sum of this parity is not `distance` to
  /// `max_distance` frames back.
  double couple_sum_difference(const CameraFrame& frame, std::int64_t distance,
                               std::int64_t max_distance);
  double couple_density(const CameraFrame& frame) const;
  ReleasedFrame release(const CameraFrame& f, DropReason reason, FrameLabel label = {});
  FrameLabel label_of(std::int64_t sequence) const;

  SequencerConfig config_;
  std::int64_t frames_per_cycle_;
  SequencerStats stats_;

  bool have_last_ = false;
  std::uint64_t last_id_ = 0;
  std::int64_t last_timestamp_ns_ = 0;
  std::int64_t position_ = 0;  ///< unwrapped frame count of the last frame
  /// position_ of the first frame after the last restart or unbridged gap: a late frame's
  /// place must not be before it.
  std::int64_t stream_start_position_ = 0;
  /// The positions received, by position modulo max_bridged_gap_frames + 1 (-1: none): a frame
  /// with an older id is late only if nothing was received at its place.
  std::vector<std::int64_t> received_;

  std::optional<CameraFrame> held_;
  std::int64_t held_position_ = 0;

  // Pair sums (uint16 per pixel) of the last two couples, by the position of their second frame.
  std::array<std::vector<std::uint16_t>, 2> sums_;
  std::array<std::int64_t, 2> sum_position_{-1, -1};
  std::vector<std::uint16_t> scratch_;
  // Scratch of the const structure measures (hunting), kept so that no frame allocates.
  mutable std::vector<double> density_scratch_;
  mutable std::vector<int> row_scratch_;

  // Hunting: structure of the continuous run ending at the last frame.
  std::vector<Structure> run_;

  // Locked: sequence number (cycle * 2n + 2 * bit + polarity) at position origin_position_.
  bool locked_ = false;
  std::int64_t origin_sequence_ = 0;
  std::int64_t origin_position_ = 0;
  std::int64_t last_emitted_cycle_ = -1;
  std::int64_t last_emitted_timestamp_ns_ = 0;
  std::int64_t last_emitted_frames_ = 0;  ///< stats_.frames at the last labelled frame
};

}  // namespace avs::camera
