// Head joint angles at a depth image's stamp, from the joint states around it: matching turns
// the camera-frame pose into the world frame with the head's angles at the data's time, which
// fall between two 1 kHz joint states (or slightly after the newest).
#pragma once

#include <cstddef>
#include <optional>

#include <boost/circular_buffer.hpp>

namespace avs::matching {

/// A short history of (pan, tilt) samples. at(): linear interpolation between the two samples
/// around the time; beyond the newest sample, extrapolation at the last velocity for at most
/// max_extrapolation_s; before the oldest, the oldest within max_extrapolation_s.
class JointHistory {
 public:
  struct Sample {
    double t_s = 0;
    double pan_rad = 0, tilt_rad = 0;
  };

  /// `keep_s`: the span of samples kept (older ones are dropped, at least two are kept).
  explicit JointHistory(double keep_s = 0.2) : keep_s_(keep_s) {}

  /// A sample older than the newest clears the history (time went back: a new run or a
  /// replay); one with the newest's time replaces it.
  void add(const Sample& sample);
  [[nodiscard]] bool empty() const { return samples_.empty(); }
  [[nodiscard]] std::size_t size() const { return samples_.size(); }
  [[nodiscard]] std::optional<Sample> at(double t_s, double max_extrapolation_s) const;

 private:
  /// Storage that only grows (doubled when full): at 1 kHz a std::deque allocated and freed a
  /// block every 21 samples (issue 16 section 3, no allocation per frame).
  boost::circular_buffer<Sample> samples_{256};
  double keep_s_;
};

}  // namespace avs::matching
