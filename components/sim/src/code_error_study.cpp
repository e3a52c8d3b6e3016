// Algorithm 1 against ground truth; see code_error_study.hpp.
#include "avs/sim/code_error_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "avs/sim/pattern_frame.hpp"

namespace avs::sim {
namespace {

CodeErrorSample compare(const std::vector<int>& decoded, std::span<const float> depth_m,
                        const Renderer& truth, int object_index, double t_s) {
  CodeErrorSample s;
  s.t_s = t_s;
  double off_sum = 0, all_sum = 0;
  std::vector<double> off_abs_mm;
  long off_depths = 0, all_depths = 0;
  const std::vector<std::int16_t>& code = truth.code();
  const std::vector<std::int16_t>& object = truth.object_index();
  const std::vector<float>& true_depth = truth.depth_m();
  for (std::size_t i = 0; i < decoded.size(); ++i) {
    if (code[i] < 0 || decoded[i] < 0) continue;
    if (object_index >= 0 && object[i] != object_index) continue;
    ++s.compared;
    const bool off = std::abs(decoded[i] - code[i]) > 1;
    s.off_by_more += off ? 1 : 0;
    if (!std::isfinite(depth_m[i])) continue;
    const double e_mm = 1e3 * (depth_m[i] - true_depth[i]);
    all_sum += e_mm * e_mm;
    ++all_depths;
    if (off) {
      off_abs_mm.push_back(std::abs(e_mm));
      off_sum += e_mm * e_mm;
      ++off_depths;
    }
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  s.depth_rms_off_mm = off_depths > 0 ? std::sqrt(off_sum / off_depths) : kNaN;
  s.depth_rms_mm = all_depths > 0 ? std::sqrt(all_sum / all_depths) : kNaN;
  s.depth_median_off_mm = kNaN;
  if (!off_abs_mm.empty()) {
    const auto middle = off_abs_mm.begin() + static_cast<std::ptrdiff_t>(off_abs_mm.size() / 2);
    std::nth_element(off_abs_mm.begin(), middle, off_abs_mm.end());
    s.depth_median_off_mm = *middle;
  }
  return s;
}

}  // namespace

CodeErrorStudy run_code_error_study(const CodeErrorStudyConfig& config) {
  Simulator sim(config.simulator, config.scene);
  decode::DecoderConfig with = config.decoder;
  with.geometry = config.simulator.renderer.geometry;
  with.code_correction = true;
  decode::DecoderConfig without = with;
  without.code_correction = false;
  decode::RollingDecoder corrected(with), uncorrected(without);
  CodeErrorStudy study;
  study.width = sim.renderer().width();
  study.height = sim.renderer().height();
  const auto frames = static_cast<std::uint64_t>(config.seconds * config.simulator.frame_rate_hz);
  const int bit_count = config.simulator.renderer.geometry.layout.bit_count;
  SimFrame positive;  // the decoders copy positives; a negative completes the pair at once
  long most_moved = -1;
  for (std::uint64_t f = 0; f < frames; ++f) {
    SimFrame frame = sim.render(f, config.head);
    const decode::PatternFrame input = pattern_frame(frame);
    const decode::DecodeResult a = corrected.push_frame(input);
    const decode::DecodeResult b = uncorrected.push_frame(input);
    // Compare once every bit has been seen (a full window).
    if (!a.depth_updated || f + 1 < static_cast<std::uint64_t>(2 * bit_count)) continue;
    const double t_s = sim.frame_time_s(f);
    const std::vector<int> code_a = corrected.code_map(), code_b = uncorrected.code_map();
    study.corrected.push_back(compare(code_a, a.depth_m, sim.renderer(), config.object_index, t_s));
    study.uncorrected.push_back(
        compare(code_b, b.depth_m, sim.renderer(), config.object_index, t_s));
    long moved = 0;
    const std::vector<std::int16_t>& object = sim.renderer().object_index();
    for (std::size_t i = 0; i < code_a.size(); ++i) {
      if (config.object_index >= 0 && object[i] != config.object_index) continue;
      moved += code_a[i] != code_b[i] ? 1 : 0;
    }
    study.moved.push_back(moved);
    if (moved > most_moved) {
      most_moved = moved;
      study.figure_t_s = t_s;
      study.figure_true_code.assign(sim.renderer().code().begin(), sim.renderer().code().end());
      study.figure_corrected_code = code_a;
      study.figure_uncorrected_code = code_b;
      study.figure_on_object.resize(object.size());
      for (std::size_t i = 0; i < object.size(); ++i) {
        study.figure_on_object[i] = object[i] == config.object_index ? 1 : 0;
      }
    }
  }
  return study;
}

}  // namespace avs::sim
