// The simulated depth sensor: scene + pan/tilt head + renderer, frame by frame. This is the
// core a capture component wraps: render(frame_index, time, head) -> image + ground truth.
#pragma once

#include <cstdint>
#include <vector>

#include "avs/sim/head.hpp"
#include "avs/sim/renderer.hpp"
#include "avs/sim/scene.hpp"

namespace avs::sim {

struct SimulatorConfig {
  RendererConfig renderer;
  HeadConfig head;
  /// Camera and projector frame rate (section 3.1: 1000 fps).
  double frame_rate_hz = 1000.0;
  /// Exposure per frame, centred on the frame time (our assumption: the whole 1 ms period).
  double exposure_s = 1e-3;
  /// Poses rendered and averaged over the exposure (motion blur); 1 = a single pose at the
  /// centre (no blur).
  int motion_blur_samples = 1;
};

/// Which pattern frame `frame_index` shows (section 4: bit 0 positive, bit 0 negative, bit 1
/// positive, ...; 2n frames per cycle).
struct PatternSlot {
  int bit_index = 0;
  bool positive = true;
  std::uint32_t cycle = 0;
};
PatternSlot pattern_slot(std::uint64_t frame_index, int bit_count);

struct SimFrame {
  std::uint64_t frame_index = 0;
  PatternSlot pattern;
  MonoImage image;
  GroundTruth truth;  ///< at the exposure centre
};

class Simulator {
 public:
  Simulator(SimulatorConfig config, Scene scene);

  const SimulatorConfig& config() const { return config_; }
  const Scene& scene() const { return scene_; }
  /// The renderer of the last frame: its ground-truth buffers describe that frame's view
  /// (for motion blur, the pose at the exposure centre).
  const Renderer& renderer() const { return renderer_; }

  double frame_time_s(std::uint64_t frame_index) const {
    return static_cast<double>(frame_index) / config_.frame_rate_hz;
  }

  /// Frame `frame_index` at its nominal time frame_index / frame_rate_hz.
  SimFrame render(std::uint64_t frame_index, const HeadState& head) {
    return render(frame_index, frame_time_s(frame_index), head);
  }
  /// Frame `frame_index` (pattern and noise) exposed around `time_s` with the head at
  /// `head` (its rates extrapolate the angles over the exposure).
  SimFrame render(std::uint64_t frame_index, double time_s, const HeadState& head);

 private:
  void set_view_at(double time_s, const HeadState& head);

  SimulatorConfig config_;
  Scene scene_;
  Renderer renderer_;
  std::vector<RenderObject> objects_;
  std::vector<Eigen::Isometry3d> last_poses_;  ///< skip the geometry pass when unchanged
  std::vector<float> blur_sum_;
};

}  // namespace avs::sim
