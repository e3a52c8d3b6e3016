// Simulator: frame schedule, head pose, motion blur, geometry caching (see simulator.hpp).
#include "avs/sim/simulator.hpp"

#include <stdexcept>
#include <string>

namespace avs::sim {

PatternSlot pattern_slot(std::uint64_t frame_index, int bit_count) {
  const auto frames_per_cycle = static_cast<std::uint64_t>(2 * bit_count);
  PatternSlot slot;
  const std::uint64_t in_cycle = frame_index % frames_per_cycle;
  slot.bit_index = static_cast<int>(in_cycle / 2);
  slot.positive = in_cycle % 2 == 0;
  slot.cycle = static_cast<std::uint32_t>(frame_index / frames_per_cycle);
  return slot;
}

Simulator::Simulator(SimulatorConfig config, Scene scene)
    : config_(std::move(config)), scene_(std::move(scene)), renderer_(config_.renderer) {
  if (!(config_.frame_rate_hz > 0) || config_.exposure_s < 0 || config_.motion_blur_samples < 1) {
    throw std::invalid_argument(
        "sim::Simulator: need frame_rate_hz > 0, exposure_s >= 0, "
        "motion_blur_samples >= 1");
  }
  for (const SceneObject& object : scene_.objects) {
    if (!object.mesh || !object.trajectory) {
      throw std::invalid_argument("sim::Simulator: object '" + object.name +
                                  "' lacks a mesh or a trajectory");
    }
    objects_.push_back({object.mesh.get(), Eigen::Isometry3d::Identity(), object.albedo});
  }
}

void Simulator::set_view_at(double time_s, const HeadState& head) {
  const Eigen::Isometry3d T_camera_world =
      T_world_camera(config_.head, head.pan_rad, head.tilt_rad).inverse();
  bool changed = last_poses_.size() != objects_.size();
  last_poses_.resize(objects_.size());
  for (std::size_t i = 0; i < objects_.size(); ++i) {
    const Eigen::Isometry3d T =
        T_camera_world * scene_.objects[i].trajectory->T_world_object(time_s);
    if (!changed && !T.isApprox(last_poses_[i], 0.0)) changed = true;
    objects_[i].T_camera_object = T;
    last_poses_[i] = T;
  }
  if (changed) renderer_.set_view(objects_);
}

SimFrame Simulator::render(std::uint64_t frame_index, double time_s, const HeadState& head) {
  SimFrame frame;
  frame.frame_index = frame_index;
  frame.pattern = pattern_slot(frame_index, config_.renderer.geometry.layout.bit_count);
  const std::uint64_t noise_key = frame_noise_key(frame_index);
  const int samples = config_.motion_blur_samples;
  // Flickering room light: its mean over this frame's exposure.
  const auto ambient =
      static_cast<float>(config_.renderer.effects.ambient.mean_gain(time_s, config_.exposure_s));
  if (samples == 1 || config_.exposure_s == 0) {
    set_view_at(time_s, head);
    renderer_.shade(frame.pattern.bit_index, frame.pattern.positive, noise_key, frame.image,
                    ambient);
  } else {
    // Sub-exposures at offsets (k + 0.5) / samples - 0.5 of the exposure; the one nearest the
    // centre is rendered last so the renderer's ground truth describes the centre.
    blur_sum_.assign(static_cast<std::size_t>(renderer_.width()) * renderer_.height(), 0.0f);
    const int centre = samples / 2;
    for (int n = 0; n < samples; ++n) {
      const int k = n < centre ? n : (n == samples - 1 ? centre : n + 1);
      const double dt = config_.exposure_s * ((k + 0.5) / samples - 0.5);
      HeadState h = head;
      h.pan_rad += head.pan_rate_rad_s * dt;
      h.tilt_rad += head.tilt_rate_rad_s * dt;
      set_view_at(time_s + dt, h);
      renderer_.accumulate(frame.pattern.bit_index, frame.pattern.positive, 1.0f / samples,
                           blur_sum_, ambient);
    }
    renderer_.finish(blur_sum_, noise_key, frame.image);
  }
  frame.truth = ground_truth(scene_, config_.head, time_s, head);
  return frame;
}

}  // namespace avs::sim
