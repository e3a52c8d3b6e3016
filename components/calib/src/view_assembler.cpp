#include "avs/calib/view_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "avs/decode/patterns.hpp"

namespace avs::calib {
ViewAssembler::ViewAssembler(const CaptureCodes& codes, int width, int height,
                             AssemblerConfig config)
    : frames_(projection_sequence(codes)), width_(width), height_(height), config_(config) {
  if (width < 1 || height < 1) throw std::invalid_argument("calib::ViewAssembler: empty frames");
  if (config.frame_id_bits < 1 || config.frame_id_bits > 64) {
    throw std::invalid_argument("calib::ViewAssembler: frame_id_bits must be 1..64");
  }
}

void ViewAssembler::reset() {
  run_.clear();
  last_id_.reset();
}

bool ViewAssembler::follows(std::uint64_t previous, std::uint64_t id) const {
  const std::uint64_t mask =
      config_.frame_id_bits == 64 ? ~0ull : ((1ull << config_.frame_id_bits) - 1);
  std::uint64_t next = (previous + 1) & mask;
  if (next == 0 && config_.frame_id_zero_skipped) next = 1;
  return id == next;
}

AssemblerResult ViewAssembler::push(std::uint64_t frame_id, const decode::ImageView8& image) {
  ++pushed_;
  AssemblerResult result;
  if (image.width != width_ || image.height != height_ || image.data == nullptr ||
      image.stride_bytes < 0 || (image.stride_bytes > 0 && image.stride_bytes < image.width)) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "frame %llu is %d x %d with rows of %td bytes, expected %d x %d: ignored",
                  static_cast<unsigned long long>(frame_id), image.width, image.height,
                  image.stride_bytes, width_, height_);
    result.rejected = why;
    return result;
  }
  if (last_id_ && !follows(*last_id_, frame_id)) {
    if (!run_.empty()) {
      result.rejected = "frame id " + std::to_string(frame_id) + " after " +
                        std::to_string(*last_id_) + ": frames lost, " +
                        std::to_string(run_.size()) + " frames dropped, starting again";
    }
    run_.clear();
  }
  last_id_ = frame_id;
  decode::GrayImage8 copy{width_, height_,
                          std::vector<std::uint8_t>(static_cast<std::size_t>(width_) * height_)};
  const std::ptrdiff_t stride = image.stride_bytes > 0 ? image.stride_bytes : image.width;
  for (int y = 0; y < height_; ++y) {
    const std::uint8_t* row = image.data + y * stride;
    std::copy(row, row + width_, copy.pixels.begin() + static_cast<std::ptrdiff_t>(y) * width_);
  }
  run_.push_back(std::move(copy));

  // The white frame of the first cycle lies within the first N frames of the run; its check
  // needs the frame N after it (the next white) too: an index of at most 2N - 1.
  const std::size_t n = frames_.size();
  if (run_.size() < 2 * n) return result;
  // Every phase consistent with the whole sequence; one is a view, more are ambiguous.
  std::string why;
  std::vector<std::size_t> consistent;
  for (const std::size_t w : white_candidates(why)) {
    const std::string problem = check_cycle(w);
    if (problem.empty()) {
      consistent.push_back(w);
    } else if (consistent.empty() && why.empty()) {
      why = problem;  // the best candidate's
    }
  }
  if (consistent.size() > 1) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "ambiguous sequence: frames %zu and %zu of a cycle both start a consistent "
                  "calibration sequence (a code bit lights all of the scene the projector "
                  "reaches in view, and its neighbours fit too): the projector must light more of "
                  "the scene (board nearer the middle of its image, or a background)",
                  consistent[0], consistent[1]);
    why = text;
  } else if (consistent.size() == 1) {
    const std::size_t best = consistent[0];
    BoardView view;  // the first white frame, then black and the codes
    view.frames.push_back(std::move(run_[best]));
    view.frames.insert(
        view.frames.end(),
        std::make_move_iterator(run_.begin() + static_cast<std::ptrdiff_t>(best + kWhiteFrames)),
        std::make_move_iterator(run_.begin() + static_cast<std::ptrdiff_t>(best + n)));
    result.view = std::move(view);
    run_.clear();
    return result;
  }
  // Give up on the oldest cycle's frames; the next cycle may be good (a board that stopped
  // moving, a projector that just started).
  result.rejected = why;
  run_.erase(run_.begin(), run_.begin() + static_cast<std::ptrdiff_t>(n));
  return result;
}

std::vector<std::size_t> ViewAssembler::white_candidates(std::string& why) const {
  // Over one cycle's frames (any N consecutive frames show each pattern once), the white frames
  // are the per-pixel maximum and the black one the minimum, up to noise. Candidates: where
  // kWhiteFrames frames near the maximum are followed by one near the minimum, best first.
  const std::size_t n = frames_.size();
  const std::size_t pixels = run_[0].pixels.size();
  std::vector<std::uint8_t> hi(pixels, 0), lo(pixels, 255);
  for (std::size_t f = 0; f < n; ++f) {
    const std::vector<std::uint8_t>& p = run_[f].pixels;
    for (std::size_t i = 0; i < pixels; ++i) {
      hi[i] = std::max(hi[i], p[i]);
      lo[i] = std::min(lo[i], p[i]);
    }
  }
  std::vector<std::size_t> lit;
  double lit_level = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (hi[i] - lo[i] >= config_.lit_threshold_dn) {
      lit.push_back(i);
      lit_level += hi[i] - lo[i];
    }
  }
  char text[320];
  if (lit.size() < config_.min_lit_fraction * static_cast<double>(pixels)) {
    std::snprintf(text, sizeof text,
                  "the projected sequence lights %.1f %% of the image (at least %.0f %%): is the "
                  "projector running the calibration sequence, and lighting the board?",
                  100.0 * lit.size() / pixels, 100 * config_.min_lit_fraction);
    why = text;
    return {};
  }
  lit_level /= static_cast<double>(lit.size());
  std::vector<double> below_max(n), above_min(n);
  for (std::size_t f = 0; f < n; ++f) {
    const std::vector<std::uint8_t>& p = run_[f].pixels;
    double a = 0, b = 0;
    for (const std::size_t i : lit) {
      a += hi[i] - p[i];
      b += p[i] - lo[i];
    }
    below_max[f] = a / static_cast<double>(lit.size()) / lit_level;
    above_min[f] = b / static_cast<double>(lit.size()) / lit_level;
  }
  // Each frame f as the first white frame: how far the white frames from f are below the
  // maximum plus how far the black one after them is above the minimum (frame n is frame 0).
  const std::size_t k = kWhiteFrames;
  std::vector<double> score(n);
  std::vector<std::size_t> candidates;
  for (std::size_t f = 0; f < n; ++f) {
    double worst_white = 0;
    for (std::size_t j = 0; j < k; ++j) {
      score[f] += below_max[(f + j) % n];
      worst_white = std::max(worst_white, below_max[(f + j) % n]);
    }
    score[f] += above_min[(f + k) % n];
    if (worst_white <= config_.max_phase_distance &&
        above_min[(f + k) % n] <= config_.max_phase_distance) {
      candidates.push_back(f);
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [&score](std::size_t a, std::size_t b) { return score[a] < score[b]; });
  if (candidates.empty()) {
    std::size_t w = 0;
    for (std::size_t f = 1; f < n; ++f) w = score[f] < score[w] ? f : w;
    std::snprintf(
        text, sizeof text,
        "no %zu white frames followed by a black one (best: %.2f below the maximum "
        "and %.2f above the minimum, of the lit level; at most %.2f each): not the "
        "calibration sequence (white x %zu, black, codes), or the scene changed during it",
        k, below_max[w], above_min[(w + k) % n], config_.max_phase_distance, k);
    why = text;
  }
  return candidates;
}

std::string ViewAssembler::check_cycle(std::size_t w) const {
  const std::size_t n = frames_.size();
  const decode::GrayImage8& white = run_[w];
  const decode::GrayImage8& black = run_[w + kWhiteFrames];
  const decode::GrayImage8& white_again = run_[w + n];
  const std::size_t pixels = white.pixels.size();
  std::vector<std::size_t> lit;
  double lit_sum = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const int d = int{white.pixels[i]} - int{black.pixels[i]};
    if (d >= config_.lit_threshold_dn) {
      lit.push_back(i);
      lit_sum += d;
    }
  }
  char why[256];
  if (lit.size() < config_.min_lit_fraction * static_cast<double>(pixels)) {
    std::snprintf(why, sizeof why,
                  "no white -> black step lighting %.0f %% of the image (best: %.1f %%): is the "
                  "projector running the calibration sequence, and lighting the board?",
                  100 * config_.min_lit_fraction, 100.0 * lit.size() / pixels);
    return why;
  }
  const double lit_mean = lit_sum / static_cast<double>(lit.size());
  for (std::size_t f = kWhiteFrames + 1; f + 1 < n; f += 2) {
    const decode::GrayImage8& pos = run_[w + f];
    const decode::GrayImage8& neg = run_[w + f + 1];
    double mismatch = 0;
    for (const std::size_t i : lit) {
      mismatch += std::abs(int{pos.pixels[i]} + int{neg.pixels[i]} - int{white.pixels[i]} -
                           int{black.pixels[i]});
    }
    mismatch /= static_cast<double>(lit.size()) * lit_mean;
    if (mismatch > config_.max_pair_mismatch) {
      std::snprintf(why, sizeof why,
                    "frames %zu and %zu from the first white one are not the complementary pair %s "
                    "(mismatch %.2f of the lit level, at most %.2f): a frame slipped, or the "
                    "projector shows another sequence",
                    f, f + 1, frames_[f].label().c_str(), mismatch, config_.max_pair_mismatch);
      return why;
    }
  }
  if (const double moved = changed_fraction(white, white_again, config_.moved_threshold_dn);
      moved > config_.max_moved_fraction) {
    std::snprintf(why, sizeof why,
                  "the scene changed during the capture (%.1f %% of the pixels of the white "
                  "frames one cycle apart differ by more than %d DN): hold the board still",
                  100.0 * moved, config_.moved_threshold_dn);
    return why;
  }
  return {};
}

double changed_fraction(const decode::GrayImage8& a, const decode::GrayImage8& b,
                        int threshold_dn) {
  if (a.pixels.size() != b.pixels.size()) return 1.0;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    changed += std::abs(int{a.pixels[i]} - int{b.pixels[i]}) > threshold_dn ? 1 : 0;
  }
  return a.pixels.empty() ? 0.0 : static_cast<double>(changed) / a.pixels.size();
}

void RepeatedReasons::add(const std::string& reason) {
  ++total_;
  std::string key;
  for (const char c : reason) {
    if ((c < '0' || c > '9') && c != '.' && c != '-' && c != '+') key.push_back(c);
  }
  if (key == last_key_) {
    ++repeats_;
    last_ = reason;
    return;
  }
  flush();
  log_(reason);
  last_ = reason;
  last_key_ = std::move(key);
  repeats_ = 1;
}

void RepeatedReasons::flush() {
  if (repeats_ > 1) log_("(the same " + std::to_string(repeats_) + " times in a row)");
  repeats_ = 0;
  last_key_.clear();
}

bool is_new_pose(const BoardView& view, const std::vector<decode::GrayImage8>& taken_whites,
                 int threshold_dn, double min_fraction) {
  if (view.frames.empty()) return false;
  return std::all_of(taken_whites.begin(), taken_whites.end(),
                     [&](const decode::GrayImage8& white) {
                       return changed_fraction(view.frames[0], white, threshold_dn) >= min_fraction;
                     });
}

StampedFrameIds::StampedFrameIds(std::int64_t period_ns) : period_ns_(period_ns) {
  if (period_ns < 1) throw std::invalid_argument("calib::StampedFrameIds: period must be > 0");
}

std::int64_t StampedFrameIds::periods_between(std::int64_t from_ns, std::int64_t stamp_ns) const {
  const std::int64_t step = stamp_ns - from_ns;
  if (step <= 0) return 0;
  const std::int64_t periods = (step + period_ns_ / 2) / period_ns_;
  const std::int64_t off = step - periods * period_ns_;
  return periods >= 1 && std::abs(off) * 4 <= period_ns_ ? periods : 0;
}

std::optional<std::uint64_t> StampedFrameIds::id(std::int64_t stamp_ns, std::string& why) {
  if (!last_stamp_ns_) {
    last_stamp_ns_ = stamp_ns;
    return last_id_ = 1;
  }
  if (const std::int64_t periods = periods_between(*last_stamp_ns_, stamp_ns); periods > 0) {
    off_grid_run_ = 0;
    last_stamp_ns_ = stamp_ns;
    last_id_ += static_cast<std::uint64_t>(periods);
    return last_id_;
  }
  off_grid_run_ = off_grid_run_ > 0 && periods_between(off_grid_stamp_ns_, stamp_ns) > 0
                      ? off_grid_run_ + 1
                      : 1;
  off_grid_stamp_ns_ = stamp_ns;
  if (off_grid_run_ >= kNewGridFrames) {
    // A grid of their own: the sequence restarted at another phase. From here on, with a gap
    // in the ids so that no run spans the two grids.
    off_grid_run_ = 0;
    last_stamp_ns_ = stamp_ns;
    last_id_ += 2;
    return last_id_;
  }
  char text[200];
  std::snprintf(text, sizeof text,
                "a frame %.3f ms after the last one on the period grid: not a whole number of "
                "pattern periods of %.3f ms (wrong --rate, or stamps not from the camera)",
                static_cast<double>(stamp_ns - *last_stamp_ns_) / 1e6,
                static_cast<double>(period_ns_) / 1e6);
  why = text;
  return std::nullopt;
}

std::vector<FrameId> projection_sequence(const CaptureCodes& codes) {
  std::vector<FrameId> frames = capture_frames(codes);
  frames.insert(frames.begin(), kWhiteFrames - 1, FrameId{FrameKind::kWhite});
  return frames;
}

decode::GrayImage8 projector_pattern(const CaptureCodes& codes, const FrameId& frame) {
  decode::GrayImage8 image{
      codes.projector_width, codes.projector_height,
      std::vector<std::uint8_t>(static_cast<std::size_t>(codes.projector_width) *
                                codes.projector_height)};
  const decode::Polarity polarity =
      frame.positive ? decode::Polarity::kPositive : decode::Polarity::kNegative;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      int lit = 0;
      switch (frame.kind) {
        case FrameKind::kWhite:
          lit = 1;
          break;
        case FrameKind::kBlack:
          lit = 0;
          break;
        case FrameKind::kColumnBit:
          lit = decode::pattern_value(codes.columns, x, frame.bit, polarity);
          break;
        case FrameKind::kRowBit:
          lit = decode::pattern_value(codes.rows, y, frame.bit, polarity);
          break;
      }
      image.pixels[static_cast<std::size_t>(y) * image.width + x] = lit ? 255 : 0;
    }
  }
  return image;
}

}  // namespace avs::calib
