// Gray-code spatial coding (paper section 4.1, Eq. 1), shared by the pattern generator,
// the decoder and the simulator's projector.
#pragma once

#include <cstdint>

namespace avs::decode {

/// How codes map onto projector rows. Paper: n = 9 bits, 265 codes over the 1060 used
/// rows, so 4 rows per code.
struct CodeLayout {
  int bit_count = 9;        ///< n
  int code_count = 265;     ///< codes actually used, 0 .. code_count-1
  int rows_per_code = 4;    ///< projector rows per code
  int first_row = 0;        ///< projector row where code 0 starts

  int used_rows() const { return code_count * rows_per_code; }
};

inline constexpr std::uint32_t binary_to_gray(std::uint32_t b) { return b ^ (b >> 1); }

inline constexpr std::uint32_t gray_to_binary(std::uint32_t g) {
  for (std::uint32_t shift = 1; shift < 32; shift <<= 1) g ^= g >> shift;
  return g;
}

/// Code of projector row `row_p`, or -1 outside the coded rows.
inline int code_of_row(const CodeLayout& layout, int row_p) {
  const int rel = row_p - layout.first_row;
  if (rel < 0 || rel >= layout.used_rows()) return -1;
  return rel / layout.rows_per_code;
}

/// Bit k (0 = most significant, as in Eq. 1) of the Gray code of `code`.
inline int gray_bit(const CodeLayout& layout, std::uint32_t code, int k) {
  return static_cast<int>((binary_to_gray(code) >> (layout.bit_count - 1 - k)) & 1u);
}

/// Eq. 1: P(x_p, y_p, k) for the positive pattern; with P_y = 2^n * rows_per_code this is
/// floor(y_p 2^k / P_y + 1/2) mod 2. Rows outside the coded range are dark (0).
inline int pattern_bit(const CodeLayout& layout, int row_p, int k) {
  const int code = code_of_row(layout, row_p);
  return code < 0 ? 0 : gray_bit(layout, static_cast<std::uint32_t>(code), k);
}

}  // namespace avs::decode
