#include "avs/calib/view_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "avs/decode/patterns.hpp"

namespace avs::calib {
namespace {

std::string frame_label(const FrameId& id) {
  const std::string name = id.file_name();
  return name.substr(0, name.size() - 4);  // without ".png"
}

}  // namespace

ViewAssembler::ViewAssembler(const CaptureCodes& codes, int width, int height,
                             AssemblerConfig config)
    : frames_(capture_frames(codes)), width_(width), height_(height), config_(config) {
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
  if (image.width != width_ || image.height != height_ || image.data == nullptr) {
    char why[128];
    std::snprintf(why, sizeof why, "frame %llu is %d x %d, expected %d x %d: ignored",
                  static_cast<unsigned long long>(frame_id), image.width, image.height, width_,
                  height_);
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
  // needs the frame N after it (the next white) too.
  const std::size_t n = frames_.size();
  if (run_.size() < 2 * n + 1) return result;
  std::string why;
  const std::optional<std::size_t> white = find_white(why);
  if (white) why = check_cycle(*white);
  if (white && why.empty()) {
    const std::size_t best = *white;
    BoardView view;
    view.frames.assign(
        std::make_move_iterator(run_.begin() + static_cast<std::ptrdiff_t>(best)),
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

std::optional<std::size_t> ViewAssembler::find_white(std::string& why) const {
  // Over one cycle's frames (any N consecutive frames show each pattern once), the white frame
  // is the per-pixel maximum and the black one the minimum, up to noise. The phase is the frame
  // that, with the frame after it, is closest to (maximum, minimum), if clearly closer than
  // any other frame. A code bit whose positive lights all of the scene the projector reaches in
  // view, and its negative none, would be as close: then the phase cannot be told from the
  // images and nothing is labelled.
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
    return std::nullopt;
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
  // Each frame f as the white frame: how far f is below the maximum plus how far f + 1 is
  // above the minimum. Frame n's pattern is frame 0's.
  std::vector<double> score(n);
  for (std::size_t f = 0; f < n; ++f) score[f] = below_max[f] + above_min[(f + 1) % n];
  std::size_t w = 0;
  for (std::size_t f = 1; f < n; ++f) w = score[f] < score[w] ? f : w;
  double second = 1e9;
  for (std::size_t f = 0; f < n; ++f) second = f != w ? std::min(second, score[f]) : second;
  if (second - score[w] < config_.min_phase_margin) {
    std::snprintf(
        text, sizeof text,
        "ambiguous sequence: frames %zu and %zu of the cycle both look like white "
        "then black (margin %.3f of the lit level, at least %.3f): a code bit lights "
        "all of the scene the projector reaches in view; the projector must light "
        "more of the scene (board nearer the middle of its image, or a background)",
        w, static_cast<std::size_t>(std::find(score.begin(), score.end(), second) - score.begin()),
        second - score[w], config_.min_phase_margin);
    why = text;
    return std::nullopt;
  }
  const double worst = config_.max_phase_distance;
  if (below_max[w] > worst || above_min[(w + 1) % n] > worst) {
    std::snprintf(text, sizeof text,
                  "no white frame followed by a black one (best: %.2f below the maximum, %.2f "
                  "above the minimum, of the lit level; at most %.2f): not the calibration "
                  "sequence (white, black, codes)",
                  below_max[w], above_min[(w + 1) % n], worst);
    why = text;
    return std::nullopt;
  }
  return w;
}

std::string ViewAssembler::check_cycle(std::size_t w) const {
  const std::size_t n = frames_.size();
  const decode::GrayImage8& white = run_[w];
  const decode::GrayImage8& black = run_[w + 1];
  const decode::GrayImage8& white_again = run_[w + n];
  const std::size_t pixels = white.pixels.size();
  std::vector<std::size_t> lit;
  double lit_sum = 0;
  std::size_t moved = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const int d = int{white.pixels[i]} - int{black.pixels[i]};
    if (d >= config_.lit_threshold_dn) {
      lit.push_back(i);
      lit_sum += d;
    }
    if (std::abs(int{white.pixels[i]} - int{white_again.pixels[i]}) > config_.moved_threshold_dn)
      ++moved;
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
  for (std::size_t f = 2; f + 1 < n; f += 2) {
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
                    "frames %zu and %zu after the white one are not the complementary pair %s "
                    "(mismatch %.2f of the lit level, at most %.2f): a frame slipped, or the "
                    "projector shows another sequence",
                    f, f + 1, frame_label(frames_[f]).c_str(), mismatch, config_.max_pair_mismatch);
      return why;
    }
  }
  if (moved > config_.max_moved_fraction * static_cast<double>(pixels)) {
    std::snprintf(why, sizeof why,
                  "the scene changed during the capture (%.1f %% of the pixels of the white "
                  "frames one cycle apart differ by more than %d DN): hold the board still",
                  100.0 * moved / pixels, config_.moved_threshold_dn);
    return why;
  }
  return {};
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
