// Bounded sample window with percentiles (round-trip times, cycle jitter).
#pragma once

#include <cstddef>
#include <vector>

namespace avs::servo {

class SampleWindow {
 public:
  explicit SampleWindow(std::size_t capacity = 8192) : capacity_(capacity) {
    samples_.reserve(capacity);
    scratch_.reserve(capacity);
  }
  void add(double value);
  /// p in [0, 100]; NaN when empty. Nearest-rank on the window's samples. Allocates nothing
  /// (the drive reports its round-trip percentiles from its cycle), so it is not safe to call
  /// from two threads at once: callers serialise it as they do add().
  double percentile(double p) const;
  std::size_t size() const { return samples_.size(); }
  void clear() {
    samples_.clear();
    next_ = 0;
  }

 private:
  std::size_t capacity_;
  std::size_t next_ = 0;
  std::vector<double> samples_;
  mutable std::vector<double> scratch_;  ///< percentile()'s copy, storage kept
};

}  // namespace avs::servo
