// Sub-code refinement: a fractional projector code per pixel from the decoded code staircase
// along the coded image direction (camera columns), so that triangulation is no longer limited
// to code centres (section 4.3's quantisation). See docs/decode.md, "Sub-code refinement".
#pragma once

#include <cstdint>
#include <vector>

#include "rolling_kernel.hpp"

namespace avs::decode::detail {

struct SubcodeParams {
  int width = 0;
  int height = 0;
  /// Rows above and below the pixel used by the fit (window 2h + 1 rows of one column).
  int half_window = 4;
  /// Neighbouring valid codes of a column that differ by more than this (per row between them)
  /// mark a surface discontinuity; a window containing one keeps the plain code.
  int max_jump = 2;
  /// Codes are below this (0: unknown). When small enough for the window's sums to fit in 16 bits
  /// ((h + 1)^2 (code_count - 1) < 2^15, the common case), the AVX2 step works on 16 columns at
  /// once.
  int code_count = 0;
};

struct SubcodePlanes {
  const float* planes = nullptr;  ///< DepthTable::subcode_planes()
  int steps = 0;                  ///< per code
  int count = 0;                  ///< planes
};

/// Per column, a least-squares line code(y) through the valid codes of the window
/// [y - h, y + h]; its value at y (clamped to the pixel's code +- 1) is the refined code.
/// Pixels whose window has a discontinuity or fewer than 3 valid codes keep their code.
class SubcodeRefiner {
 public:
  /// `isa`: kAvx2 only where the CPU has it (best_kernel_isa()); every one gives bit-identical
  /// codes (tests/decode/subcode_test.cpp).
  explicit SubcodeRefiner(SubcodeParams params, KernelIsa isa = best_kernel_isa());

  /// Told each refined row as soon as it is final (rows in order 0 .. height - 1), so that the
  /// next stage reads it while it is still in the cache.
  class RowSink {
   public:
    virtual void row_done(int y, const float* refined_row) = 0;

   protected:
    ~RowSink() = default;
  };

  /// codes: width * height, -1 where invalid. refined: width * height, NaN where invalid.
  void refine(const std::int16_t* codes, float* refined, RowSink* sink = nullptr);

  const SubcodeParams& params() const { return params_; }
  /// Whether the window's sums fit in 16 bits (SubcodeParams::code_count).
  bool narrow_sums() const { return narrow_; }

 private:
  SubcodeParams params_;
  KernelIsa isa_;
  // Per column running sums over the window's valid codes about the output row (d = y - y0;
  // exact integers): count, d, d^2, code, code * d, discontinuities.
  std::vector<std::int32_t> n_, sd_, sdd_, sc_, scd_, jumps_;
  // The same in 16 bits, and the previous valid row, for the AVX2 step on 16 columns.
  bool narrow_ = false;
  std::vector<std::int16_t> n16_, sd16_, sdd16_, sc16_, scd16_, jumps16_, previous_y16_;
  std::vector<std::uint8_t> jump_;        ///< per pixel: a discontinuity to the previous valid code
  std::vector<std::int16_t> previous_;    ///< per column: last valid code seen
  std::vector<std::int32_t> previous_y_;  ///< per column: its row
};

/// Binary code per pixel from the rolling window's Gray words, -1 unless every bit is known
/// and the code is < code_count.
void codes_from_gray(const std::uint16_t* gray, const std::uint16_t* valid, std::uint16_t full,
                     int code_count, std::int16_t* codes, int pixels);

/// Depth through the nearest sub-code plane of each fractional code (NaN codes, codes outside
/// the table and depths outside (min, max) give NaN), with the best instruction set of this
/// CPU (best_kernel_isa()).
void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels);
/// The same with instruction set `isa` (kAvx2 only where the CPU has it; kSse2 = kScalar here):
/// every one gives bit-identical depths (tests/decode/subcode_test.cpp).
void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels, KernelIsa isa);

}  // namespace avs::decode::detail
