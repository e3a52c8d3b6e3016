// Algorithm 1 (section 4.4) measured against ground truth (issue 19 item 2): the simulator's
// frames go to two rolling decoders, one with the code correction and one without, and every
// depth map of each is compared with the renderer's true code and depth at the newest frame.
// Plain C++ over the simulator and decoder cores, no I/O.
#pragma once

#include <cstdint>
#include <vector>

#include "avs/decode/rolling_decoder.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {

struct CodeErrorStudyConfig {
  SimulatorConfig simulator;
  Scene scene;
  HeadState head;  ///< held still (no tracking): the code boundaries move over the target
  double seconds = 1.0;
  /// Both decoders' settings; code_correction is set on one and off on the other.
  decode::DecoderConfig decoder;
  /// Pixels of this scene object only (its index in scene.objects); -1: every coded pixel.
  int object_index = 0;
};

/// One depth map of one decoder against the truth of its newest frame.
struct CodeErrorSample {
  double t_s = 0;               ///< newest frame's time
  long compared = 0;            ///< pixels with a decoded and a true code (on the object)
  long off_by_more = 0;         ///< |decoded - true code| > 1
  double depth_rms_off_mm = 0;  ///< depth error RMS over those pixels with a depth (NaN: none)
  double depth_rms_mm = 0;      ///< depth error RMS over every compared pixel with a depth
  /// Median |depth error| over the off-by-more pixels with a depth (NaN: none): the RMS is
  /// dominated by the few pixels that took the wall's code at the silhouette.
  double depth_median_off_mm = 0;
  double off_fraction() const { return compared > 0 ? double(off_by_more) / compared : 0.0; }
};

struct CodeErrorStudy {
  std::vector<CodeErrorSample> corrected, uncorrected;  ///< per depth map, same times
  /// Pixels (of the compared ones) whose code the correction changed, per depth map.
  std::vector<long> moved;
  /// The depth map with the most moved pixels, for the figure: its time, the true code per
  /// pixel (-1: none), each decoder's code, and the pixels the correction changed.
  double figure_t_s = 0;
  std::vector<int> figure_true_code, figure_corrected_code, figure_uncorrected_code;
  std::vector<std::uint8_t> figure_on_object;  ///< 1 where the studied object is seen
  int width = 0, height = 0;
};

/// Renders `seconds` of the scene at the simulator's frame rate and decodes it twice.
CodeErrorStudy run_code_error_study(const CodeErrorStudyConfig& config);

}  // namespace avs::sim
