// A rendered frame as the rolling decoder's input: the one conversion from the simulator's
// pattern slot (bit, polarity, cycle) to decode::PatternFrame.
#pragma once

#include "avs/decode/rolling_decoder.hpp"
#include "avs/sim/simulator.hpp"

namespace avs::sim {

/// Views `frame`'s image (which must outlive the result, or be a negative the decoder consumes
/// at once: the decoder copies positives).
inline decode::PatternFrame pattern_frame(const SimFrame& frame) {
  decode::PatternFrame input;
  input.image = {frame.image.pixels.data(), frame.image.width, frame.image.height, 0};
  input.bit_index = frame.pattern.bit_index;
  input.polarity =
      frame.pattern.positive ? decode::Polarity::kPositive : decode::Polarity::kNegative;
  input.cycle = frame.pattern.cycle;
  return input;
}

}  // namespace avs::sim
