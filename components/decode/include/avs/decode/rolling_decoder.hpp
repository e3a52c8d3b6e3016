// Rolling Gray-code decoder (sections 4.1-4.4): binarise positive/negative pairs (Eq. 2), keep
// the newest n bits per pixel (Eq. 3), convert to binary, correct codes (Algorithm 1) and
// triangulate after every pair, i.e. a depth map at 500 Hz from 1000 fps frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "avs/decode/patterns.hpp"
#include "avs/decode/sensor_geometry.hpp"
#include "avs/decode/triangulation.hpp"

namespace avs::decode {

namespace detail {
class SubcodeRefiner;
}

/// A non-owning 8-bit monochrome image.
struct ImageView8 {
  const std::uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  std::ptrdiff_t stride_bytes = 0;  ///< 0 means width
};

/// One captured frame with the pattern it shows. The sequence number of a frame is
/// cycle * 2n + 2 * bit_index + polarity: frames are placed by these fields, never by arrival.
struct PatternFrame {
  ImageView8 image;
  int bit_index = 0;
  Polarity polarity = Polarity::kPositive;
  std::int64_t cycle = 0;
};

enum class TriangulationMethod {
  kRayPlaneTable,   ///< per-pixel ray x per-code plane tables (fast path)
  kReferenceSolve,  ///< per-pixel 3x3 solve of Eq. 4 (reference)
};

struct DecoderConfig {
  SensorGeometry geometry = default_sensor_geometry();
  int threshold_psi = 10;       ///< Eq. 2 threshold on I_pos - I_neg, 8-bit intensity units
  bool code_correction = true;  ///< Algorithm 1 (section 4.4)
  /// A bit is used only while it is at most this many pairs old; 0 means bit_count, i.e. only
  /// the newest n pairs (a dropped pair invalidates its bit until it is measured again).
  int max_bit_age_pairs = 0;
  float min_depth_m = 0.05f;  ///< depths outside (min, max) are reported as NaN
  float max_depth_m = 20.0f;
  TriangulationMethod triangulation = TriangulationMethod::kRayPlaneTable;
  bool compute_point_map = false;  ///< also fill DecodeResult::points_camera_m
  /// Sub-code refinement (docs/decode.md): 0 = off, triangulate code centres (section 4.3's
  /// quantisation); h > 0 = fit a line to the codes of the 2h + 1 rows around each pixel in its
  /// camera column (the coded direction) and triangulate the fitted fractional code through
  /// sub-code planes (DepthTable::subcode_planes). Table triangulation only.
  int subcode_half_window = 0;
  /// Valid codes of a column differing by more than this per row mark a discontinuity: a
  /// window containing one keeps the plain code.
  int subcode_max_jump = 2;
  /// Sub-code planes per code (the fitted code is rounded to 1 / steps of a code).
  int subcode_steps = 16;
};

struct DecoderStats {
  std::int64_t frames_received = 0;
  std::int64_t pairs_decoded = 0;
  std::int64_t dropped_frames = 0;  ///< gaps in the sequence numbers
  std::int64_t out_of_order_frames =
      0;  ///< frames older than (or equal to) the newest seen; discarded
  std::int64_t incomplete_pairs = 0;  ///< negatives whose positive never arrived
  /// Frames more than two whole cycles behind the newest: the source started again (its
  /// counters from 0, as a restarted camera or simulator does); the decoder started over.
  std::int64_t source_restarts = 0;
};

struct DecodeResult {
  bool depth_updated = false;  ///< a pair completed and depth_m was recomputed
  std::int64_t cycle = -1;     ///< of the newest pair used
  int bit_index = -1;
  int width = 0;
  int height = 0;
  /// Depth along the camera z axis in metres, NaN where invalid. Points into the decoder;
  /// valid until its next call.
  std::span<const float> depth_m;
  /// X, Y, Z per pixel in the camera frame (m), NaN where invalid; empty unless
  /// DecoderConfig::compute_point_map.
  std::span<const Eigen::Vector3f> points_camera_m;
  DecoderStats stats;
  /// How old the map's depth information is on average, in pairs before the newest pair: the
  /// ages of the window's bits weighted by how many code transitions each bit decides (bit k,
  /// 0 = MSB, flips at 2^k of the 2^n - 1 Gray-code transitions), so mostly the finest bits'.
  /// A moving surface's decoded depth lags the newest frame by about this times 2 frame
  /// periods (+ half a frame period: a pair's mid-time); docs/decode.md. NaN before a full window.
  double effective_age_pairs = std::numeric_limits<double>::quiet_NaN();
};

/// Algorithm 1 on one Gray word: writes bit k (0 = MSB) of an n-bit word and, when that bit
/// changed, sets bit k+1 to 1 and the lower bits to 0. Returns the new Gray word.
std::uint32_t update_gray_with_correction(std::uint32_t gray, int k, int new_bit, int bit_count);

class RollingDecoder {
 public:
  explicit RollingDecoder(DecoderConfig config);
  ~RollingDecoder();
  RollingDecoder(RollingDecoder&&) noexcept;
  RollingDecoder& operator=(RollingDecoder&&) noexcept;

  /// Feed one frame (the image is copied when it is a positive). Returns depth_updated = true
  /// when the frame completed a positive/negative pair.
  DecodeResult push_frame(const PatternFrame& frame);
  /// Same, but a depth map computed by this call is written to `depth_out` (width * height
  /// floats, row-major) instead of the decoder's own buffer, e.g. straight into an outgoing
  /// message; DecodeResult::depth_m then views `depth_out`. The decoder's own buffer (and
  /// the point map) is left as it was.
  DecodeResult push_frame(const PatternFrame& frame, std::span<float> depth_out);
  /// Feed a complete pair without copying (same bookkeeping as two push_frame calls).
  DecodeResult push_pair(const ImageView8& positive, const ImageView8& negative, int bit_index,
                         std::int64_t cycle);

  /// Forget all bits and statistics.
  void reset();

  /// Takes the fields of `config` that may change between two frames (threshold_psi,
  /// code_correction, min_depth_m, max_depth_m, max_bit_age_pairs; 0 = bit_count); the
  /// others (geometry, triangulation, sub-code refinement, point map) stay as constructed.
  /// The bits kept so far stay; the next pair uses the new values. Throws
  /// std::invalid_argument, changing nothing, when a value is out of range.
  void retune(const DecoderConfig& config);

  /// Binary code per pixel of the current window (after correction), -1 where invalid.
  std::vector<int> code_map() const;
  const DecoderConfig& config() const { return config_; }
  const DecoderStats& stats() const { return stats_; }
  const DepthTable& table() const { return table_; }

 private:
  DecodeResult apply_pair(const ImageView8& positive, const ImageView8& negative, int bit_index,
                          std::int64_t pair_index, float* depth_out);
  bool accept_sequence(std::int64_t sequence);
  std::uint16_t fresh_mask() const;
  DecodeResult make_result(bool updated) const;
  DecodeResult push_frame_to(const PatternFrame& frame, float* depth_out);
  void update_reference(const ImageView8& positive, const ImageView8& negative, int bit_index,
                        bool all_fresh);
  void fill_point_map();
  void refine_depth(float* depth_out);

  DecoderConfig config_;
  DepthTable table_;
  ReferenceTriangulator reference_;
  int width_ = 0;
  int height_ = 0;
  int bit_count_ = 0;
  std::vector<std::uint16_t> gray_;   ///< Gray word per pixel, bit k at position n-1-k
  std::vector<std::uint16_t> valid_;  ///< 1 where that bit was binarised unambiguously
  std::vector<float> depth_m_;
  std::vector<Eigen::Vector3f> points_;
  std::vector<std::uint8_t> pending_positive_;
  std::int64_t pending_positive_sequence_ = -1;
  std::int64_t newest_sequence_ = -1;
  std::vector<std::int64_t> pair_of_bit_;  ///< pair index of the newest measurement of each bit
  std::int64_t newest_pair_cycle_ = -1;
  int newest_pair_bit_ = -1;
  DecoderStats stats_;
  std::unique_ptr<detail::SubcodeRefiner> refiner_;  ///< set when subcode_half_window > 0
  std::vector<std::int16_t> codes_;                  ///< refinement scratch
  std::vector<float> refined_row_;  ///< one row of fractional codes, reused by every row
};

/// Full-cycle decode (section 4.1): all 2n frames of one cycle, matched by bit index and
/// polarity, decoded at once without correction. Same triangulation as the rolling decoder.
struct FullCycleResult {
  std::vector<float> depth_m;  ///< NaN where invalid
  std::vector<int> code;       ///< binary code, -1 where invalid (before sub-code refinement)
};
FullCycleResult decode_full_cycle(const DecoderConfig& config,
                                  std::span<const PatternFrame> frames);

}  // namespace avs::decode
