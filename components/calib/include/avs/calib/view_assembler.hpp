// Which calibration frame is this camera frame? (issue 14, `avs calib capture --source camera`)
//
// While a board pose is captured the projector loops the calibration sequence of
// projection_sequence(): white three times, black, column bits +/-, row bits +/- (N frames), one
// camera frame per pattern, from any phase. Why three whites: in any three consecutive code
// frames two are a complementary pair, which cannot both light all of the scene, so no code
// frames, whatever part of the projector's image the scene covers, look like the start of the
// sequence (with a single white, a code bit constant over the scene, positive all lit and
// negative all dark, does: measured in the simulator for the row code's MSB). A camera gives frame
// ids, not pattern numbers, so the assembler finds the sequence in the images and never hands out a
// mislabelled view:
//
//   * It keeps a run of frames with consecutive ids (a gap in the ids starts a new run: a frame
//     lost in transport would shift every label after it).
//   * Phase: over any N consecutive frames (each pattern once) the white frames are the
//     per-pixel maximum and the black frame the minimum, up to noise. The phase is where three
//     frames near the maximum are followed by one near the minimum (`max_phase_distance`).
//     Should two phases fit and pass the checks below, nothing is labelled ("ambiguous"). The
//     projector must light at least `min_lit_fraction` of the image by `lit_threshold_dn`.
//   * Structure: in the cycle from that white frame, every bit's positive and negative must be
//     complementary where the projector lights the scene: mean |pos + neg - white - black| over
//     lit pixels at most `max_pair_mismatch` of the mean (white - black). A slip of one frame
//     without a trace in the ids fails here.
//   * Stillness: the two white frames, one cycle apart, must agree (at most `max_moved_fraction`
//     of the pixels differ by more than `moved_threshold_dn`): a board moved or shaken during
//     the capture is refused, not averaged.
//
// The view is the first cycle's frames, as the camera gave them, in capture_frames() order (the
// first white frame stands for the three). Core: no I/O, no threads;
// frames are copied into the assembler (a view is 36 frames, not a 500 Hz path).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "avs/calib/capture.hpp"
#include "avs/decode/png_io.hpp"
#include "avs/decode/rolling_decoder.hpp"

namespace avs::calib {

struct AssemblerConfig {
  int frame_id_bits = 16;             ///< GigE Vision block ids: 16 bits (64: no wrap)
  bool frame_id_zero_skipped = true;  ///< GigE Vision: id 0 is invalid, 65535 -> 1
  int lit_threshold_dn = 8;           ///< white - black at least this: lit by the projector
  double min_lit_fraction = 0.02;     ///< of the image, lit in the white -> black step
  double max_pair_mismatch = 0.25;    ///< see the header comment
  /// The white frames and the black one after them are each at most this far from the
  /// cycle's per-pixel maximum and minimum (mean distance over lit pixels, as a fraction of the lit
  /// level max - min).
  double max_phase_distance = 0.15;
  int moved_threshold_dn = 24;
  double max_moved_fraction = 0.005;
};

/// What one push() gave.
struct AssemblerResult {
  /// A complete, checked view (frames in capture_frames() order, name and truth empty).
  std::optional<BoardView> view;
  /// Why a run of frames was given up ("" when none was): logged by the caller; the
  /// assembler goes on with the frames after it.
  std::string rejected;
};

class ViewAssembler {
 public:
  /// Frames of `width` x `height` 8-bit pixels, the sequence of `codes`.
  ViewAssembler(const CaptureCodes& codes, int width, int height, AssemblerConfig config = {});

  /// Takes one camera frame (copied). A frame of another size is rejected with its reason.
  AssemblerResult push(std::uint64_t frame_id, const decode::ImageView8& image);
  /// Forgets every frame (the board is about to move).
  void reset();

  int frames_per_cycle() const { return static_cast<int>(frames_.size()); }
  std::int64_t frames_pushed() const { return pushed_; }

 private:
  bool follows(std::uint64_t previous, std::uint64_t id) const;
  /// Where the white frame may be in the run's first cycle, best first (none: `why`).
  std::vector<std::size_t> white_candidates(std::string& why) const;
  /// Checks the run from white frame `w`; "" when it is a good view.
  std::string check_cycle(std::size_t w) const;

  std::vector<FrameId> frames_;  ///< the sequence, capture_frames() order
  int width_;
  int height_;
  AssemblerConfig config_;
  std::vector<decode::GrayImage8> run_;  ///< consecutive frames, oldest first
  std::optional<std::uint64_t> last_id_;
  std::int64_t pushed_ = 0;
};

/// Reasons for frames and cycles not used, told without flooding the log: a reason is passed to
/// `log` when it differs from the one before (ignoring its numbers: "frame id 12 after 9" and
/// "frame id 40 after 37" are the same reason), and when another comes, or at flush(), how many
/// times the one before came in a row.
class RepeatedReasons {
 public:
  explicit RepeatedReasons(std::function<void(const std::string&)> log) : log_(std::move(log)) {}
  void add(const std::string& reason);
  void flush();
  std::int64_t total() const { return total_; }
  const std::string& last() const { return last_; }

 private:
  std::function<void(const std::string&)> log_;
  std::string last_;
  std::string last_key_;
  std::int64_t repeats_ = 0;
  std::int64_t total_ = 0;
};

/// Whether `view` shows a pose not taken yet: its white frame differs from each of
/// `taken_whites` (the white frames of the views taken) in at least `min_fraction` of the pixels
/// by more than `threshold_dn`.
bool is_new_pose(const BoardView& view, const std::vector<decode::GrayImage8>& taken_whites,
                 int threshold_dn, double min_fraction);

/// Frame ids for frames known by their stamps only (a recording of /camera/image_raw: the
/// camera's stamps, one exposure per projector pattern): each step from the last frame on the
/// grid must be a whole number of pattern periods, within a quarter period; the id advances by
/// it (a step of k periods is k - 1 frames lost: the assembler starts again). A frame off the
/// grid is left out and the grid kept, unless kNewGridFrames frames in a row are off it and on
/// a grid of their own (the camera or the projector restarted at another phase): the grid then
/// moves to them, with a jump in the ids (the assembler starts again).
class StampedFrameIds {
 public:
  static constexpr int kNewGridFrames = 3;
  explicit StampedFrameIds(std::int64_t period_ns);
  /// The frame's id (64 bits, from 1), or nullopt and why (off the period grid, or not after
  /// the last frame on it).
  std::optional<std::uint64_t> id(std::int64_t stamp_ns, std::string& why);

 private:
  /// Whole periods from `from_ns` to `stamp_ns` (>= 1), or 0 when not on that grid.
  std::int64_t periods_between(std::int64_t from_ns, std::int64_t stamp_ns) const;

  std::int64_t period_ns_;
  std::optional<std::int64_t> last_stamp_ns_;
  std::uint64_t last_id_ = 0;
  std::int64_t off_grid_stamp_ns_ = 0;  ///< the last frame off the grid
  int off_grid_run_ = 0;                ///< frames in a row off the grid, on a grid of their own
};

/// The fraction of pixels of `a` and `b` that differ by more than `threshold_dn` (1 when their
/// sizes differ).
double changed_fraction(const decode::GrayImage8& a, const decode::GrayImage8& b, int threshold_dn);

/// White frames at the start of the projected sequence.
inline constexpr std::size_t kWhiteFrames = 3;

/// What the projector loops during a camera capture: kWhiteFrames white frames, then the rest
/// of capture_frames() (black, column bits, row bits).
std::vector<FrameId> projection_sequence(const CaptureCodes& codes);

/// The projector image of one calibration frame (codes.projector_width x projector_height,
/// 0 or 255): what the projector's flash holds for it (`avs calib patterns`) and what the
/// simulator's projector shows.
decode::GrayImage8 projector_pattern(const CaptureCodes& codes, const FrameId& frame);

}  // namespace avs::calib
