// Rendered frames of the ken on the manipulator trajectory (head still), replayed endlessly,
// for the allocation tests of issue 16 section 3 (hot_path_allocations_test.cpp renders them
// for the cores, container_allocations_test.cpp publishes them into a decode component).
#pragma once

#include <memory>
#include <vector>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/matching/pipeline.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::testing {

/// Two whole cycles of rendered frames of the ken on the manipulator trajectory, played
/// forwards and backwards by cycle (as avs bench pipeline's pattern_replay).
struct Recording {
  sim::SimulatorConfig config;
  std::vector<sim::SimFrame> frames;
  int per_cycle = 18;

  Recording() {
    const matching::ObjectModel ken = matching::load_object_model("ken");
    sim::Scene scene;
    sim::SceneObject target;
    target.name = "ken";
    target.mesh = std::make_shared<const geometry::Mesh>(ken.mesh);
    sim::ManipulatorMotionConfig motion;
    target.trajectory = std::make_shared<sim::ManipulatorTrajectory>(motion);
    scene.objects.push_back(target);
    scene.objects.push_back(sim::make_background_plane(2.0));
    sim::Simulator simulator(config, scene);
    per_cycle = 2 * config.renderer.geometry.layout.bit_count;
    for (int k = 0; k < 3 * per_cycle; ++k) {
      frames.push_back(simulator.render(static_cast<std::uint64_t>(k), 0.5 + k * 1e-3, {}));
    }
  }

  /// Frame k of the endless replay, its cycle counting up.
  decode::PatternFrame frame(int k) const {
    const int cycles = static_cast<int>(frames.size()) / per_cycle;
    const int replay_cycle = k / per_cycle;
    const int p = replay_cycle % (2 * (cycles - 1));
    const int recorded = p < cycles ? p : 2 * (cycles - 1) - p;
    const sim::SimFrame& f = frames[static_cast<std::size_t>(recorded * per_cycle + k % per_cycle)];
    decode::PatternFrame input;
    input.image = {f.image.pixels.data(), f.image.width, f.image.height, 0};
    input.bit_index = f.pattern.bit_index;
    input.polarity = f.pattern.positive ? decode::Polarity::kPositive : decode::Polarity::kNegative;
    input.cycle = static_cast<std::uint32_t>(replay_cycle);
    return input;
  }
};

inline const Recording& recording() {
  static const Recording r;
  return r;
}

}  // namespace avs::testing
