// Sub-code refinement: a fractional projector code per pixel from the decoded code staircase
// along the coded image direction (camera columns), so that triangulation is no longer limited
// to code centres (section 4.3's quantisation). See docs/decode.md, "Sub-code refinement".
#pragma once

#include <cstdint>
#include <vector>

#include "avs/decode/triangulation.hpp"
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
  /// ((2h + 1) code_count and h (h + 1)(code_count - 1) below 2^15, the common case), the AVX2
  /// step works on 16 columns at once.
  int code_count = 0;
};

struct SubcodePlanes {
  const float* planes = nullptr;  ///< DepthTable::subcode_planes()
  int steps = 0;                  ///< per code
  int count = 0;                  ///< planes
  /// DepthTable::linear_subcode_planes(): when set, the planes in closed form (used instead of
  /// the table).
  const LinearSubcodePlanes* linear = nullptr;
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

  /// Whether `refined` holds every row or one row (width floats) that each row overwrites once
  /// the sink has taken it (the rows stay in the cache; 4 bytes per pixel less to write back).
  enum class RefinedRows { kAll, kOneRowForAll };

  /// codes: width * height, -1 where invalid. refined: width * height (or width with
  /// kOneRowForAll, which needs a sink), NaN where invalid.
  void refine(const std::int16_t* codes, float* refined, RowSink* sink = nullptr,
              RefinedRows rows = RefinedRows::kAll);

  const SubcodeParams& params() const { return params_; }
  /// Whether the window's sums fit in 16 bits (SubcodeParams::code_count).
  bool narrow_sums() const { return narrow_; }

 private:
  SubcodeParams params_;
  KernelIsa isa_;
  // Per column running sums over the window's valid codes about the output row (d = y - y0;
  // exact integers): count, d, d^2, code, code * d, discontinuities.
  std::vector<std::int32_t> n_, sd_, sdd_, sc_, scd_, jumps_;
  // Count, code and discontinuities in 16 bits, and the previous valid row, for the AVX2 step
  // on 16 columns (which takes the offset sums from the rows where it needs them).
  bool narrow_ = false;
  std::vector<std::int16_t> n16_, sc16_, jumps16_, previous_y16_;
  /// Per pixel of the last 2h + 2 rows (a ring): a discontinuity to the previous valid code.
  std::vector<std::uint8_t> jump_;
  std::vector<std::int16_t> previous_;    ///< per column: last valid code seen
  std::vector<std::int32_t> previous_y_;  ///< per column: its row
};

/// Binary code per pixel from the rolling window's Gray words, -1 unless every bit is known
/// and the code is < code_count. The decoder has them from its update pass
/// (PairUpdateArgs::codes); this is that pass's reference (tests) and the bench's pass apart.
void codes_from_gray(const std::uint16_t* gray, const std::uint16_t* valid, std::uint16_t full,
                     int code_count, std::int16_t* codes, int pixels);

/// Depth through the plane of each fractional code (NaN codes, codes outside the coded range
/// and depths outside (min, max) give NaN): in closed form when planes.linear is set, else
/// through the nearest sub-code plane of the table; with the best instruction set of this CPU
/// (best_kernel_isa()).
void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels);
/// The same with instruction set `isa` (kAvx2 only where the CPU has it; kSse2 = kScalar here):
/// every one gives bit-identical depths (tests/decode/subcode_test.cpp).
void triangulate_subcode(const float* refined, const SubcodePlanes& planes, const float* ray_x,
                         const float* ray_y, float min_depth_m, float max_depth_m, float* depth,
                         int pixels, KernelIsa isa);

/// One image row of a camera whose rays are separable (DepthTable::column_ray_x, and its
/// row_ray_y for this row: the same values as the per-pixel tables): 8 bytes per pixel less to
/// read, the same depths bit for bit as triangulate_subcode on that row.
void triangulate_subcode_row(const float* refined_row, const SubcodePlanes& planes,
                             const float* column_ray_x, float row_ray_y, float min_depth_m,
                             float max_depth_m, float* depth_row, int width);
void triangulate_subcode_row(const float* refined_row, const SubcodePlanes& planes,
                             const float* column_ray_x, float row_ray_y, float min_depth_m,
                             float max_depth_m, float* depth_row, int width, KernelIsa isa);

}  // namespace avs::decode::detail
