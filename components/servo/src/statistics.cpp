#include "avs/servo/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace avs::servo {

void SampleWindow::add(double value) {
  if (capacity_ == 0) return;
  if (samples_.size() < capacity_) {
    samples_.push_back(value);
  } else {
    samples_[next_] = value;
    next_ = (next_ + 1) % capacity_;
  }
}

double SampleWindow::percentile(double p) const {
  if (samples_.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double>& copy = scratch_;
  copy.assign(samples_.begin(), samples_.end());
  const double rank = std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * copy.size());
  const auto index = static_cast<std::size_t>(std::max(1.0, rank)) - 1;
  std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(index), copy.end());
  return copy[index];
}

}  // namespace avs::servo
