// Bounded sample window with percentiles (round-trip times, cycle jitter).
#pragma once

#include <cstddef>
#include <vector>

namespace avs::servo {

class SampleWindow {
 public:
  explicit SampleWindow(std::size_t capacity = 8192) : capacity_(capacity) {
    samples_.reserve(capacity);
  }
  void add(double value);
  /// p in [0, 100]; NaN when empty. Nearest-rank on the window's samples.
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
};

}  // namespace avs::servo
