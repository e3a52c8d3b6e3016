#include "avs/matching/joint_history.hpp"

namespace avs::matching {

void JointHistory::add(const Sample& s) {
  if (!samples_.empty() && s.t_s < samples_.back().t_s) samples_.clear();  // time went back
  if (!samples_.empty() && s.t_s == samples_.back().t_s) samples_.pop_back();
  if (samples_.full()) samples_.set_capacity(2 * samples_.capacity());
  samples_.push_back(s);
  while (samples_.size() > 2 && samples_.back().t_s - samples_.front().t_s > keep_s_) {
    samples_.pop_front();
  }
}

std::optional<JointHistory::Sample> JointHistory::at(double t_s, double max_extrapolation_s) const {
  if (samples_.empty()) return std::nullopt;
  if (samples_.size() == 1 || t_s <= samples_.front().t_s) {
    if (samples_.front().t_s - t_s > max_extrapolation_s) return std::nullopt;
    return samples_.front();
  }
  std::size_t i = 1;
  while (i + 1 < samples_.size() && samples_[i].t_s < t_s) ++i;
  const Sample& a = samples_[i - 1];
  const Sample& b = samples_[i];
  if (t_s - b.t_s > max_extrapolation_s) return std::nullopt;  // history too old
  const double w = (t_s - a.t_s) / (b.t_s - a.t_s);            // > 1: extrapolation
  return Sample{t_s, a.pan_rad + w * (b.pan_rad - a.pan_rad),
                a.tilt_rad + w * (b.tilt_rad - a.tilt_rad)};
}

}  // namespace avs::matching
