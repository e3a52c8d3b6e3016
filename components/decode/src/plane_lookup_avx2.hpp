// The (a, b, c) of 8 depth planes (rows of 4 floats: a, b, c, 0) as three AVX2 registers, by
// 8 row loads and a 4x4 transpose per 128-bit lane (pixels i and i + 4 share a load). Profiled
// on Zen 4, three hardware gathers took over half of the decode loop; loads and shuffles give
// the same values in about half the time. Used by the rolling kernel and the sub-code path.
#pragma once

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

namespace avs::decode::detail {

struct Planes8 {
  __m256 a, b, c;
};

/// rows[k]: the plane of pixel k (k = 0..7).
__attribute__((target("avx2"))) inline Planes8 load_planes8(const float* const rows[8]) {
  const auto pair = [rows](int k) __attribute__((target("avx2"))) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(rows[k])),
                                _mm_loadu_ps(rows[k + 4]), 1);
  };
  const __m256 r04 = pair(0);
  const __m256 r15 = pair(1);
  const __m256 r26 = pair(2);
  const __m256 r37 = pair(3);
  const __m256 ab01 = _mm256_unpacklo_ps(r04, r15);  // a0 a1 b0 b1 | a4 a5 b4 b5
  const __m256 ab23 = _mm256_unpacklo_ps(r26, r37);  // a2 a3 b2 b3 | a6 a7 b6 b7
  const __m256 c01 = _mm256_unpackhi_ps(r04, r15);   // c0 c1 0 0 | c4 c5 0 0
  const __m256 c23 = _mm256_unpackhi_ps(r26, r37);   // c2 c3 0 0 | c6 c7 0 0
  return {_mm256_shuffle_ps(ab01, ab23, _MM_SHUFFLE(1, 0, 1, 0)),
          _mm256_shuffle_ps(ab01, ab23, _MM_SHUFFLE(3, 2, 3, 2)),
          _mm256_shuffle_ps(c01, c23, _MM_SHUFFLE(1, 0, 1, 0))};
}

}  // namespace avs::decode::detail

#endif
