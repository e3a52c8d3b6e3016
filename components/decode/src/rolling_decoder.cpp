#include "avs/decode/rolling_decoder.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "rolling_kernel.hpp"
#include "subcode.hpp"

namespace avs::decode {
namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

std::ptrdiff_t stride_of(const ImageView8& image) {
  return image.stride_bytes == 0 ? image.width : image.stride_bytes;
}

void check_image(const ImageView8& image, int width, int height, const char* what) {
  if (image.data == nullptr || image.width != width || image.height != height ||
      stride_of(image) < width) {
    throw std::invalid_argument(std::string("rolling decoder: ") + what + " image is " +
                                std::to_string(image.width) + "x" + std::to_string(image.height) +
                                (image.data == nullptr ? " (null)" : "") + ", expected " +
                                std::to_string(width) + "x" + std::to_string(height));
  }
}

void check_bit(int bit_index, int bit_count) {
  if (bit_index < 0 || bit_index >= bit_count) {
    throw std::invalid_argument("rolling decoder: bit index " + std::to_string(bit_index) +
                                " outside 0.." + std::to_string(bit_count - 1));
  }
}

bool in_range(float z, const DecoderConfig& c) {
  return z > c.min_depth_m && z < c.max_depth_m;
}

std::unique_ptr<detail::SubcodeRefiner> make_refiner(const DecoderConfig& c) {
  if (c.subcode_half_window <= 0) return nullptr;
  if (c.triangulation != TriangulationMethod::kRayPlaneTable) {
    throw std::invalid_argument(
        "rolling decoder: sub-code refinement (subcode_half_window " +
        std::to_string(c.subcode_half_window) +
        ") is implemented for table triangulation only, not for the reference solve");
  }
  if (c.subcode_steps < 1 || c.subcode_steps > 256) {
    throw std::invalid_argument("rolling decoder: subcode_steps " +
                                std::to_string(c.subcode_steps) + " outside 1..256");
  }
  return std::make_unique<detail::SubcodeRefiner>(detail::SubcodeParams{
      c.geometry.camera.width, c.geometry.camera.height, c.subcode_half_window, c.subcode_max_jump,
      c.geometry.layout.code_count});
}

/// The table's sub-code planes (in closed form where it has them) for detail::triangulate_subcode.
detail::SubcodePlanes subcode_planes_of(const DepthTable& table) {
  return {table.subcode_planes(), table.subcode_steps(), table.subcode_plane_count(),
          table.linear_subcode_planes()};
}

/// Depth from fractional codes through the sub-code planes (NaN codes give NaN), all pixels.
void triangulate_subcode(const DepthTable& table, const float* refined, const DecoderConfig& c,
                         float* depth_out) {
  detail::triangulate_subcode(refined, subcode_planes_of(table), table.ray_x(), table.ray_y(),
                              c.min_depth_m, c.max_depth_m, depth_out, table.pixel_count());
}

/// The same one row at a time, as the refiner finishes each (the row still in the cache).
class RowTriangulator final : public detail::SubcodeRefiner::RowSink {
 public:
  RowTriangulator(const DepthTable& table, const DecoderConfig& c, float* depth_out, int width)
      : table_(table), c_(c), depth_out_(depth_out), width_(width) {}
  void row_done(int y, const float* refined_row) override {
    const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(y) * width_;
    const detail::SubcodePlanes planes = subcode_planes_of(table_);
    if (table_.column_ray_x() != nullptr) {  // separable rays: 8 bytes per pixel less to read
      detail::triangulate_subcode_row(refined_row, planes, table_.column_ray_x(),
                                      table_.row_ray_y()[y], c_.min_depth_m, c_.max_depth_m,
                                      depth_out_ + offset, width_);
      return;
    }
    detail::triangulate_subcode(refined_row, planes, table_.ray_x() + offset,
                                table_.ray_y() + offset, c_.min_depth_m, c_.max_depth_m,
                                depth_out_ + offset, width_);
  }

 private:
  const DepthTable& table_;
  const DecoderConfig& c_;
  float* depth_out_;
  int width_;
};

}  // namespace

std::uint32_t update_gray_with_correction(std::uint32_t gray, int k, int new_bit, int bit_count) {
  const int position = bit_count - 1 - k;
  const std::uint32_t bit_mask = 1u << position;
  const bool changed = ((gray >> position) & 1u) != static_cast<std::uint32_t>(new_bit & 1);
  gray = (gray & ~bit_mask) | (static_cast<std::uint32_t>(new_bit & 1) << position);
  if (changed && position > 0) {
    // Algorithm 1: g_{k+1} -> 1, g_l -> 0 for l >= k + 2.
    gray = (gray & ~(bit_mask - 1u)) | (bit_mask >> 1);
  }
  return gray;
}

namespace {

/// The tunable fields of `c` checked; max_bit_age_pairs 0 replaced by `bit_count`.
DecoderConfig checked_tuning(DecoderConfig c, int bit_count) {
  if (c.threshold_psi < 0 || c.threshold_psi > 255) {
    throw std::invalid_argument("rolling decoder: threshold_psi " +
                                std::to_string(c.threshold_psi) + " outside 0..255");
  }
  if (c.max_bit_age_pairs == 0) c.max_bit_age_pairs = bit_count;
  if (c.max_bit_age_pairs < bit_count) {
    throw std::invalid_argument("rolling decoder: max_bit_age_pairs " +
                                std::to_string(c.max_bit_age_pairs) +
                                " is smaller than the bit count " + std::to_string(bit_count));
  }
  if (!(c.min_depth_m < c.max_depth_m)) {
    throw std::invalid_argument("rolling decoder: min_depth_m " + std::to_string(c.min_depth_m) +
                                " must be below max_depth_m " + std::to_string(c.max_depth_m));
  }
  return c;
}

}  // namespace

RollingDecoder::RollingDecoder(DecoderConfig config)
    : config_(std::move(config)),
      table_(config_.geometry, config_.subcode_half_window > 0 ? config_.subcode_steps : 0),
      reference_(config_.geometry),
      width_(config_.geometry.camera.width),
      height_(config_.geometry.camera.height),
      bit_count_(config_.geometry.layout.bit_count) {
  config_ = checked_tuning(std::move(config_), bit_count_);
  const auto pixels = static_cast<std::size_t>(width_) * height_;
  gray_.assign(pixels, 0);
  valid_.assign(pixels, 0);
  depth_m_.assign(pixels, kNan);
  pending_positive_.assign(pixels, 0);
  if (config_.compute_point_map) points_.assign(pixels, Eigen::Vector3f::Constant(kNan));
  pair_of_bit_.assign(static_cast<std::size_t>(bit_count_),
                      std::numeric_limits<std::int64_t>::min() / 2);
  refiner_ = make_refiner(config_);
  if (refiner_) {
    codes_.assign(pixels, -1);
    refined_row_.assign(static_cast<std::size_t>(width_), kNan);
  }
}

RollingDecoder::~RollingDecoder() = default;
RollingDecoder::RollingDecoder(RollingDecoder&&) noexcept = default;
RollingDecoder& RollingDecoder::operator=(RollingDecoder&&) noexcept = default;

void RollingDecoder::retune(const DecoderConfig& config) {
  DecoderConfig c = config_;
  c.threshold_psi = config.threshold_psi;
  c.code_correction = config.code_correction;
  c.min_depth_m = config.min_depth_m;
  c.max_depth_m = config.max_depth_m;
  c.max_bit_age_pairs = config.max_bit_age_pairs;
  config_ = checked_tuning(std::move(c), bit_count_);
}

void RollingDecoder::reset() {
  std::fill(gray_.begin(), gray_.end(), 0);
  std::fill(valid_.begin(), valid_.end(), 0);
  std::fill(depth_m_.begin(), depth_m_.end(), kNan);
  std::fill(points_.begin(), points_.end(), Eigen::Vector3f::Constant(kNan));
  std::fill(pair_of_bit_.begin(), pair_of_bit_.end(), std::numeric_limits<std::int64_t>::min() / 2);
  pending_positive_sequence_ = -1;
  newest_sequence_ = -1;
  newest_pair_cycle_ = -1;
  newest_pair_bit_ = -1;
  stats_ = {};
}

bool RollingDecoder::accept_sequence(std::int64_t sequence) {
  // A late frame is a few frames behind; one more than two whole cycles behind comes from a
  // source that started counting again (its process restarted, issue 20 section 5). Without
  // this, every frame of the new stream would be "out of order" until it overtook the old
  // counter: no depth for as long as the old stream had run. The old bits describe the old
  // stream: start over with the new one.
  if (newest_sequence_ >= 0 && sequence < newest_sequence_ - 4 * bit_count_) {
    DecoderStats kept = stats_;
    reset();
    stats_ = kept;
    ++stats_.source_restarts;
  }
  if (sequence <= newest_sequence_) {
    ++stats_.out_of_order_frames;  // late or repeated: its slot has passed, never reassigned
    return false;
  }
  if (newest_sequence_ >= 0) stats_.dropped_frames += sequence - newest_sequence_ - 1;
  newest_sequence_ = sequence;
  return true;
}

DecodeResult RollingDecoder::push_frame(const PatternFrame& frame) {
  return push_frame_to(frame, depth_m_.data());
}

DecodeResult RollingDecoder::push_frame(const PatternFrame& frame, std::span<float> depth_out) {
  if (depth_out.size() != depth_m_.size()) {
    throw std::invalid_argument("rolling decoder: depth output holds " +
                                std::to_string(depth_out.size()) + " floats, expected " +
                                std::to_string(depth_m_.size()));
  }
  return push_frame_to(frame, depth_out.data());
}

DecodeResult RollingDecoder::push_frame_to(const PatternFrame& frame, float* depth_out) {
  ++stats_.frames_received;
  check_bit(frame.bit_index, bit_count_);
  check_image(frame.image, width_, height_, "frame");
  if (frame.cycle < 0) throw std::invalid_argument("rolling decoder: negative cycle counter");
  const std::int64_t sequence = frame.cycle * 2 * bit_count_ + 2 * frame.bit_index +
                                (frame.polarity == Polarity::kNegative ? 1 : 0);
  if (!accept_sequence(sequence)) return make_result(false);
  if (frame.polarity == Polarity::kPositive) {
    const std::ptrdiff_t stride = stride_of(frame.image);
    for (int y = 0; y < height_; ++y) {
      std::memcpy(pending_positive_.data() + static_cast<std::ptrdiff_t>(y) * width_,
                  frame.image.data + y * stride, static_cast<std::size_t>(width_));
    }
    pending_positive_sequence_ = sequence;
    return make_result(false);
  }
  if (pending_positive_sequence_ != sequence - 1) {
    ++stats_.incomplete_pairs;  // its positive was lost: bit k keeps its old, ageing value
    return make_result(false);
  }
  pending_positive_sequence_ = -1;
  const ImageView8 positive{pending_positive_.data(), width_, height_, width_};
  return apply_pair(positive, frame.image, frame.bit_index,
                    frame.cycle * bit_count_ + frame.bit_index, depth_out);
}

DecodeResult RollingDecoder::push_pair(const ImageView8& positive, const ImageView8& negative,
                                       int bit_index, std::int64_t cycle) {
  stats_.frames_received += 2;
  check_bit(bit_index, bit_count_);
  check_image(positive, width_, height_, "positive");
  check_image(negative, width_, height_, "negative");
  if (cycle < 0) throw std::invalid_argument("rolling decoder: negative cycle counter");
  const std::int64_t sequence = cycle * 2 * bit_count_ + 2 * bit_index;
  if (!accept_sequence(sequence)) {
    ++stats_.out_of_order_frames;  // the negative of the same late pair
    return make_result(false);
  }
  accept_sequence(sequence + 1);
  pending_positive_sequence_ = -1;
  return apply_pair(positive, negative, bit_index, cycle * bit_count_ + bit_index, depth_m_.data());
}

std::uint16_t RollingDecoder::fresh_mask() const {
  const std::int64_t newest_pair = newest_sequence_ / 2;
  std::uint16_t mask = 0;
  for (int k = 0; k < bit_count_; ++k) {
    const std::int64_t age = newest_pair - pair_of_bit_[k];
    if (age >= 0 && age < config_.max_bit_age_pairs)
      mask |= static_cast<std::uint16_t>(1u << (bit_count_ - 1 - k));
  }
  return mask;
}

DecodeResult RollingDecoder::apply_pair(const ImageView8& positive, const ImageView8& negative,
                                        int bit_index, std::int64_t pair_index, float* depth_out) {
  pair_of_bit_[bit_index] = pair_index;
  newest_pair_cycle_ = pair_index / bit_count_;
  newest_pair_bit_ = bit_index;
  ++stats_.pairs_decoded;
  const auto full = static_cast<std::uint16_t>((1u << bit_count_) - 1u);
  const bool all_fresh = fresh_mask() == full;

  detail::PairUpdateArgs args;
  args.positive = positive.data;
  args.positive_stride = stride_of(positive);
  args.negative = negative.data;
  args.negative_stride = stride_of(negative);
  args.width = width_;
  args.height = height_;
  args.gray = gray_.data();
  args.valid = valid_.data();
  args.bit_position = bit_count_ - 1 - bit_index;
  args.threshold_psi = config_.threshold_psi;
  args.code_correction = config_.code_correction;
  args.full_mask = full;
  const bool table_path = config_.triangulation == TriangulationMethod::kRayPlaneTable;
  if (all_fresh && table_path && !refiner_) {
    args.depth_m = depth_out;
    args.ray_x = table_.ray_x();
    args.ray_y = table_.ray_y();
    args.column_ray_x = table_.column_ray_x();
    args.row_ray_y = table_.row_ray_y();
    args.planes = table_.planes();
    args.invalid_index = table_.invalid_index();
    args.min_depth_m = config_.min_depth_m;
    args.max_depth_m = config_.max_depth_m;
  }
  if (refiner_) {  // the codes for the refinement come out of the same pass
    args.codes = codes_.data();
    args.code_count = config_.geometry.layout.code_count;
  }
  detail::update_pair(args);

  const std::size_t pixels = depth_m_.size();
  if (!all_fresh) {
    std::fill_n(depth_out, pixels, kNan);  // a bit of the window is missing
  } else if (refiner_) {
    refine_depth(depth_out);
  } else if (!table_path) {
    const int code_count = config_.geometry.layout.code_count;
    for (std::size_t i = 0; i < pixels; ++i) {
      const int code = static_cast<int>(gray_to_binary(gray_[i]));
      float z = kNan;
      if (valid_[i] == full && code < code_count) z = reference_.depth(static_cast<int>(i), code);
      depth_out[i] = in_range(z, config_) ? z : kNan;
    }
  }
  if (config_.compute_point_map && depth_out == depth_m_.data()) fill_point_map();
  DecodeResult result = make_result(true);
  result.depth_m = std::span<const float>(depth_out, pixels);
  return result;
}

void RollingDecoder::refine_depth(float* depth_out) {
  // codes_: from update_pair, with the bits of this pair.
  RowTriangulator triangulate_rows(table_, config_, depth_out, width_);
  refiner_->refine(codes_.data(), refined_row_.data(), &triangulate_rows,
                   detail::SubcodeRefiner::RefinedRows::kOneRowForAll);
}

void RollingDecoder::fill_point_map() {
  const float* rx = table_.ray_x();
  const float* ry = table_.ray_y();
  for (std::size_t i = 0; i < depth_m_.size(); ++i) {
    const float z = depth_m_[i];
    points_[i] = {z * rx[i], z * ry[i], z};
  }
}

DecodeResult RollingDecoder::make_result(bool updated) const {
  DecodeResult result;
  result.depth_updated = updated;
  result.cycle = newest_pair_cycle_;
  result.bit_index = newest_pair_bit_;
  result.width = width_;
  result.height = height_;
  result.depth_m = depth_m_;
  result.points_camera_m = points_;
  result.stats = stats_;
  const auto full = static_cast<std::uint16_t>((1u << bit_count_) - 1u);
  if (newest_sequence_ >= 0 && fresh_mask() == full) {
    const std::int64_t newest_pair = newest_sequence_ / 2;
    double age = 0;
    for (int k = 0; k < bit_count_; ++k) {
      age += static_cast<double>(1u << k) * static_cast<double>(newest_pair - pair_of_bit_[k]);
    }
    result.effective_age_pairs = age / static_cast<double>(full);
  }
  return result;
}

std::vector<int> RollingDecoder::code_map() const {
  const auto full = static_cast<std::uint16_t>((1u << bit_count_) - 1u);
  std::vector<int> codes(gray_.size(), -1);
  if (fresh_mask() != full) return codes;
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const int code = static_cast<int>(gray_to_binary(gray_[i]));
    if (valid_[i] == full && code < config_.geometry.layout.code_count) codes[i] = code;
  }
  return codes;
}

FullCycleResult decode_full_cycle(const DecoderConfig& config,
                                  std::span<const PatternFrame> frames) {
  const SensorGeometry& g = config.geometry;
  const int n = g.layout.bit_count;
  const int width = g.camera.width;
  const int height = g.camera.height;
  std::vector<const PatternFrame*> positive(static_cast<std::size_t>(n), nullptr);
  std::vector<const PatternFrame*> negative(static_cast<std::size_t>(n), nullptr);
  for (const PatternFrame& frame : frames) {
    check_bit(frame.bit_index, n);
    check_image(frame.image, width, height, "frame");
    auto& slot = frame.polarity == Polarity::kPositive ? positive : negative;
    slot[static_cast<std::size_t>(frame.bit_index)] = &frame;
  }
  for (int k = 0; k < n; ++k) {
    if (positive[k] == nullptr || negative[k] == nullptr) {
      throw std::invalid_argument("decode_full_cycle: no " +
                                  std::string(positive[k] == nullptr ? "positive" : "negative") +
                                  " frame for bit " + std::to_string(k));
    }
  }
  const DepthTable table(g, config.subcode_half_window > 0 ? config.subcode_steps : 0);
  const ReferenceTriangulator reference(g);
  const std::unique_ptr<detail::SubcodeRefiner> refiner = make_refiner(config);
  const bool table_path = config.triangulation == TriangulationMethod::kRayPlaneTable;
  FullCycleResult result;
  result.depth_m.assign(static_cast<std::size_t>(width) * height, kNan);
  result.code.assign(result.depth_m.size(), -1);
  std::vector<std::int16_t> refine_codes(refiner ? result.depth_m.size() : 0, -1);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint32_t gray = 0;
      bool known = true;
      for (int k = 0; k < n; ++k) {  // Eqs. 2-3
        const auto& p = positive[k]->image;
        const auto& q = negative[k]->image;
        const int difference = p.data[y * stride_of(p) + x] - q.data[y * stride_of(q) + x];
        known = known && (difference > config.threshold_psi || difference < -config.threshold_psi);
        gray = (gray << 1) | (difference > config.threshold_psi ? 1u : 0u);
      }
      const int code = static_cast<int>(gray_to_binary(gray));
      if (!known || code >= g.layout.code_count) continue;
      const int i = y * width + x;
      if (refiner) refine_codes[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(code);
      const float z = table_path ? table.depth(i, code) : reference.depth(i, code);
      if (!in_range(z, config)) continue;
      result.depth_m[i] = z;
      result.code[i] = code;
    }
  }
  if (refiner) {
    std::vector<float> refined(refine_codes.size(), kNan);
    refiner->refine(refine_codes.data(), refined.data());
    triangulate_subcode(table, refined.data(), config, result.depth_m.data());
  }
  return result;
}

}  // namespace avs::decode
