// How much longer than usual a test may wait for its children: AVS_TEST_WAIT_SCALE (a factor,
// default 1). The limits of a test are set for the plain build on a loaded 2-core machine; an
// instrumented build (ThreadSanitizer: 5-15x slower) runs the same test with a larger factor
// (`bash tools/run.sh test --tsan --closed-loop`) instead of a test with other limits.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace avs::testing {

/// AVS_TEST_WAIT_SCALE as a number in [1, 1000]; 1 when unset. A bad value is an error (a
/// typo must not silently give the short limits).
inline double wait_scale() {
  const char* text = std::getenv("AVS_TEST_WAIT_SCALE");
  if (text == nullptr || *text == '\0') return 1.0;
  char* end = nullptr;
  const double scale = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(scale) || scale < 1.0 || scale > 1000.0) {
    throw std::invalid_argument(std::string("AVS_TEST_WAIT_SCALE='") + text +
                                "': expected a number from 1 to 1000");
  }
  return scale;
}

/// `limit` times wait_scale(), in milliseconds.
template <class Rep, class Period>
std::chrono::milliseconds scaled(std::chrono::duration<Rep, Period> limit) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(
      std::llround(std::chrono::duration<double, std::milli>(limit).count() * wait_scale())));
}

}  // namespace avs::testing
