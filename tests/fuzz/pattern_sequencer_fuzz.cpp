// libFuzzer target: the camera side's protocol layer, the PatternSequencer (frame ids and
// timestamps from a GenICam camera -> which Gray-code pattern each frame shows). What a camera
// sends is outside input: ids that skip, repeat, go back or restart, timestamps that jump or
// wrap, frames whose content slipped one exposure. The header promises the sequencer NEVER
// mislabels; this target checks it, not only that nothing crashes:
//   * every frame shows a real pattern rendered here (Gray-code stripes of Eq. 1 for the bit and
//     polarity of its true position in the projection order), so each label the sequencer gives
//     is compared with the truth;
//   * every frame pushed is released exactly once, at most one is held between calls, labels
//     are in range and their sequence numbers (cycle * 2n + 2 * bit + polarity) only grow;
//   * the statistics add up.
// The input: byte 0 the bit count n (2..5) and the id width; then 3 bytes a frame: what the
// camera does (advance, lose frames, repeat, deliver late, slip an exposure without a trace in
// its ids, restart, or send raw 64-bit id and timestamp noise) and by how much.
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <vector>

#include "avs/camera/pattern_sequencer.hpp"

namespace {

using avs::camera::CameraFrame;
using avs::camera::DropReason;
using avs::camera::PatternSequencer;
using avs::camera::Released;
using avs::camera::SequencerConfig;
using avs::decode::Polarity;

constexpr int kWidth = 64;
constexpr int kHeight = 2;
constexpr std::int64_t kPeriodNs = 1'000'000;  // 1000 fps

[[noreturn]] void fail(const char* what, long long a, long long b) {
  std::fprintf(stderr, "pattern_sequencer_fuzz: %s (%lld, %lld)\n", what, a, b);
  std::abort();
}

/// The frame at `position` of the projection order (bit 0 +, bit 0 -, ..., bit n-1 -): Gray
/// code of the column's code index (Eq. 1), bit k counted from the most significant.
std::vector<std::uint8_t> render(int n, std::int64_t position) {
  const std::int64_t in_cycle = position % (2 * n);
  const int bit = static_cast<int>(in_cycle / 2);
  const bool negative = (in_cycle % 2) == 1;
  std::vector<std::uint8_t> image(kWidth * kHeight);
  for (int x = 0; x < kWidth; ++x) {
    const int code = x * (1 << n) / kWidth;
    const int gray = code ^ (code >> 1);
    const bool lit = (((gray >> (n - 1 - bit)) & 1) != 0) != negative;
    for (int y = 0; y < kHeight; ++y) image[y * kWidth + x] = lit ? 200 : 20;
  }
  return image;
}

std::vector<std::uint8_t> noise(std::uint8_t a, std::uint8_t b) {
  std::vector<std::uint8_t> image(kWidth * kHeight);
  for (std::size_t p = 0; p < image.size(); ++p) {
    image[p] = static_cast<std::uint8_t>(a + p * b);
  }
  return image;
}

struct Sent {
  std::int64_t position = -1;  ///< true position in the projection order; -1: noise image
  std::vector<std::uint8_t> image;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  SequencerConfig config;
  config.bit_count = 2 + data[0] % 4;
  config.frame_id_bits = (data[0] & 0x10) != 0 ? 64 : 16;
  const int n = config.bit_count;
  PatternSequencer sequencer(config);

  std::map<std::uint64_t, Sent> pending;  // token -> what the frame was, until released
  std::map<std::uint64_t, std::int64_t> truth_of;  // token -> true position (-1: noise)
  std::uint64_t next_token = 1;
  std::int64_t position = 0;  // true position of the next frame
  std::uint64_t id = 1;
  std::int64_t timestamp_ns = 1'000'000'000;
  std::int64_t last_sequence = -1;
  std::deque<CameraFrame> recent;  // for repeats and late deliveries
  std::int64_t released_count = 0;
  // One slip per run: two slips with no checked pair between them (the first one's pair
  // partner lost in a gap) shift the content by a whole pair, which has the same sum as the
  // pair the ids announce; the header says what pair sums can and cannot see.
  bool slipped = false;

  auto check = [&](const Released& released) {
    for (int k = 0; k < released.count; ++k) {
      const auto& f = released.frames[static_cast<std::size_t>(k)];
      const auto it = pending.find(f.token);
      if (it == pending.end()) fail("released a token not held", static_cast<long long>(f.token), 0);
      ++released_count;
      if (f.reason == DropReason::kNone) {
        const int bit = f.label.bit_index;
        if (bit < 0 || bit >= n) fail("bit out of range", bit, n);
        const std::int64_t sequence =
            f.label.cycle * 2 * n + 2 * bit + (f.label.polarity == Polarity::kNegative ? 1 : 0);
        if (sequence <= last_sequence) fail("sequence number went back", sequence, last_sequence);
        last_sequence = sequence;
        const std::int64_t truth = it->second.position;
        if (truth < 0) fail("labelled a noise image", sequence, 0);
        if (sequence % (2 * n) != truth % (2 * n)) {
          fail("mislabelled: label position in cycle vs truth", sequence % (2 * n),
               truth % (2 * n));
        }
      }
      pending.erase(it);
    }
    if (pending.size() > 1) fail("more than one frame held", static_cast<long long>(pending.size()), 1);
  };

  auto push = [&](std::uint64_t frame_id, std::int64_t stamp_ns, std::int64_t truth,
                  std::vector<std::uint8_t> image) {
    const std::uint64_t token = next_token++;
    Sent& sent = pending[token];
    sent.position = truth;
    truth_of[token] = truth;
    sent.image = std::move(image);
    CameraFrame frame;
    frame.frame_id = frame_id;
    frame.timestamp_ns = stamp_ns;
    frame.image = {sent.image.data(), kWidth, kHeight, 0};
    frame.token = token;
    recent.push_back(frame);
    if (recent.size() > 8) recent.pop_front();
    check(sequencer.push(frame));
  };

  for (std::size_t i = 1; i + 3 <= size; i += 3) {
    const std::uint8_t op = data[i];
    const std::uint8_t a = data[i + 1];
    const std::uint8_t b = data[i + 2];
    // Jitter within +-0.25 period (the camera clock is not exact).
    const std::int64_t jitter_ns = (static_cast<std::int64_t>(a) - 128) * kPeriodNs / 512;
    switch (op % 10) {
      default:  // 0-4: the next exposure
        break;
      case 5: {  // frames lost in transport: the ids skip as many as the exposures
        const int lost = 1 + b % 16;
        position += lost;
        id += static_cast<std::uint64_t>(lost);
        timestamp_ns += lost * kPeriodNs;
        break;
      }
      case 6: {  // a frame sent again (same id) or completed late (an older id)
        if (recent.empty()) break;
        const CameraFrame old = recent[b % recent.size()];
        // The caller may drop a released frame's image: render what it showed again.
        const std::int64_t truth = truth_of.at(old.token);
        std::vector<std::uint8_t> image = truth >= 0 ? render(n, truth) : noise(a, b);
        push(old.frame_id, old.timestamp_ns, truth, std::move(image));
        continue;
      }
      case 7:  // the camera slipped an exposure without a trace in its ids (once: see below)
        if (!slipped) position += 1;
        slipped = true;
        break;
      case 8:  // the camera restarted: ids from 1, its clock from anywhere
        id = 1;
        timestamp_ns = static_cast<std::int64_t>(b) * kPeriodNs;
        break;
      case 9: {  // raw noise: any id, any timestamp, any image
        std::uint64_t raw_id = 0;
        std::int64_t raw_stamp = 0;
        for (int k = 0; k < 8; ++k) {
          raw_id = (raw_id << 8) | static_cast<std::uint64_t>((a * (k + 1)) ^ b);
          raw_stamp = static_cast<std::int64_t>((static_cast<std::uint64_t>(raw_stamp) << 8) |
                                                static_cast<std::uint64_t>(b * (k + 3) + a));
        }
        push(raw_id, raw_stamp, -1, noise(a, b));
        continue;
      }
    }
    // A noise frame or a restart breaks the truth of nothing: the next real frame still shows
    // the pattern of its position.
    push(id, timestamp_ns + jitter_ns, position, render(n, position));
    position += 1;
    id += 1;
    if (config.frame_id_bits == 16 && id % 65536 == 0) id = 1;  // GigE Vision: 65535 -> 1
    timestamp_ns += kPeriodNs;
  }
  check(sequencer.flush());
  if (!pending.empty()) fail("frames never released", static_cast<long long>(pending.size()), 0);
  const auto& s = sequencer.stats();
  if (s.frames != released_count) fail("frames pushed vs released", s.frames, released_count);
  if (s.labelled < 0 || s.labelled > s.frames) fail("labelled count", s.labelled, s.frames);
  return 0;
}
