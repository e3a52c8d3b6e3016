// Issue 16 section 3 for the capture side of a real rig: the camera component lends each
// Aravis buffer to its message without a copy. Lending allocates nothing once warm: the
// messages (runtime::LentSamplePool) and the buffers' leases (AravisCamera) are kept from frame
// to frame, and a buffer still goes back to the stream once nobody holds its frame (else the
// stream, with few buffers, would run dry and the frames stop).
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "allocation_counter.hpp"
#include "aravis_camera.hpp"
#include "avs/msg/type_support.hpp"
#include "avs/runtime/lent_sample_pool.hpp"
#include "avs/runtime/sample.hpp"
#include "sim_gige_camera.hpp"

namespace avs::testing {
namespace {

using PatternFrame = msgs::avs_msgs::PatternFrame;

dds_sequence_uint8& image_bytes(PatternFrame& p) {
  return p.image.data;
}

/// A driver's buffers and one lease object per buffer, made once: a lease is out while its
/// use count is above 1.
struct Buffers {
  explicit Buffers(int n) : bytes(static_cast<std::size_t>(n), std::vector<std::uint8_t>(64)) {
    for (int i = 0; i < n; ++i) {
      leases.push_back(std::make_shared<int>(i));
    }
  }
  int out() const {
    int n = 0;
    for (const auto& lease : leases) n += lease.use_count() > 1 ? 1 : 0;
    return n;
  }
  std::vector<std::vector<std::uint8_t>> bytes;
  std::vector<std::shared_ptr<const void>> leases;
};

TEST(CameraAllocations, LentSamplesAllocateNothingOnceWarmAndLeasesGoWithTheLastHolder) {
  Buffers buffers(4);
  runtime::LentSamplePool<PatternFrame> pool(&image_bytes, 3);
  // The two frames a subscriber still holds while the next is lent, as a decode queue would
  // (a ring: a std::deque would allocate by itself).
  std::array<std::shared_ptr<const PatternFrame>, 2> held;
  long counted = -1;
  for (int k = 0; k < 1100; ++k) {
    if (k == 100) {
      reset_counted_allocations();
      count_allocations_on_this_thread(true);
    }
    const auto& bytes = buffers.bytes[static_cast<std::size_t>(k % 4)];
    auto m = pool.lend(bytes.data(), bytes.size(), buffers.leases[static_cast<std::size_t>(k % 4)]);
    runtime::set_string(m->header.frame_id, "camera_optical");
    runtime::set_string(m->image.encoding, "mono8");
    m->cycle = static_cast<std::uint32_t>(k);
    ASSERT_EQ(m->image.data._buffer, bytes.data()) << "lent, not copied";
    ASSERT_FALSE(m->image.data._release);
    held[static_cast<std::size_t>(k % 2)] = std::move(m);
    // The two held and the one just let go (until the next lend): never more.
    ASSERT_LE(buffers.out(), 3);
  }
  count_allocations_on_this_thread(false);
  counted = counted_allocations();
  EXPECT_EQ(counted, 0) << "allocations over 1000 lent frames";
  EXPECT_LE(pool.kept(), 3u);

  // A held sample keeps its lease; let go, the lease goes at the next release_unused().
  EXPECT_GE(buffers.out(), 2);
  held = {};
  EXPECT_GE(buffers.out(), 2) << "the pool still holds the leases";
  pool.release_unused();
  EXPECT_EQ(buffers.out(), 0) << "both frames let go of their buffers";
}

/// Aravis's fake camera on loopback at 200 Hz, 512 x 512, each frame one grey level.
struct LoopbackCamera {
  static constexpr int kWidth = 512, kHeight = 512;
  static camera::SimGigECameraConfig config() {
    camera::SimGigECameraConfig c;
    c.frame_rate_hz = 200;
    return c;
  }
  camera::SimGigECamera served{config(), kWidth, kHeight, [](std::uint64_t k, std::uint8_t* out) {
                                 std::memset(out, static_cast<int>(k % 251), kWidth * kHeight);
                               }};
};

camera::CameraConfig loopback_config(int buffers) {
  camera::CameraConfig config;
  config.device_id = "127.0.0.1";
  config.trigger_mode = camera::TriggerMode::kFreeRun;
  config.frame_rate_hz = 200;
  config.width = LoopbackCamera::kWidth;
  config.height = LoopbackCamera::kHeight;
  config.buffer_count = buffers;
  config.socket_buffer_bytes = 8 << 20;
  return config;
}

/// Frames over GigE Vision on loopback from Aravis's fake camera, taken on this thread with
/// AravisCamera::next() and each held for two more frames (as the sequencer holds them) with
/// only 4 stream buffers: counted over 300 frames after 60, nothing allocated on this thread.
TEST(CameraAllocations, AravisFramesAreLentWithoutAllocatingAndTheirBuffersComeBack) {
  const LoopbackCamera loopback;
  camera::AravisCamera camera(loopback_config(4));
  camera.start();
  std::array<camera::CapturedFrame, 2> held;  // a ring: a std::deque would allocate by itself
  int frames = 0, complete = 0;
  long counted = -1;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (frames < 360 && std::chrono::steady_clock::now() < deadline) {
    if (frames == 60) {
      reset_counted_allocations();
      count_allocations_on_this_thread(true);
    }
    std::optional<camera::CapturedFrame> f = camera.next(std::chrono::milliseconds(200));
    if (!f) continue;
    ++frames;
    if (f->complete) {
      ++complete;
      EXPECT_EQ(f->data[0], f->data[f->size - 1]);
    }
    held[static_cast<std::size_t>(frames % 2)] = std::move(*f);
  }
  count_allocations_on_this_thread(false);
  counted = counted_allocations();
  held = {};
  camera.stop();
  ASSERT_EQ(frames, 360) << "the stream ran dry: buffers not returned?";
  EXPECT_GT(complete, 180);  // a loaded host may lose packets on loopback; not the subject here
  EXPECT_EQ(counted, 0) << "allocations over 300 frames lent by AravisCamera";
}

/// The camera component's arrangement with few buffers: each frame lent into a pooled sample
/// that a subscriber on another thread holds for 12 ms (more than two frame periods), so the
/// stream runs out of buffers again and again. A buffer the subscriber lets go while next()
/// waits comes back within its 1 ms step through the release hook; without it the capture
/// stalled until next()'s timeout (4 s here) each time.
TEST(CameraAllocations, BuffersLetGoWhileTheCaptureWaitsComeBackWithinAStep) {
  const LoopbackCamera loopback;
  camera::AravisCamera camera(loopback_config(3));
  runtime::LentSamplePool<PatternFrame> pool(&image_bytes);
  camera.set_release_hook([&pool] { pool.release_unused(); });

  // The subscriber: holds each sample 12 ms after it arrived, then lets it go.
  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::shared_ptr<const PatternFrame>>>
      queue;
  bool done = false;
  std::thread subscriber([&] {
    std::unique_lock lock(mutex);
    while (!done || !queue.empty()) {
      if (queue.empty()) {
        arrived.wait(lock);
        continue;
      }
      const auto due = queue.front().first + std::chrono::milliseconds(12);
      if (std::chrono::steady_clock::now() < due) {
        arrived.wait_until(lock, due);
        continue;
      }
      queue.pop_front();  // lets go of the sample
    }
  });

  camera.start();
  int frames = 0;
  auto last = std::chrono::steady_clock::now();
  std::chrono::steady_clock::duration longest{};
  const auto deadline = last + std::chrono::seconds(60);
  while (frames < 200 && std::chrono::steady_clock::now() < deadline) {
    std::optional<camera::CapturedFrame> f = camera.next(std::chrono::milliseconds(4000));
    const auto now = std::chrono::steady_clock::now();
    if (frames > 10) longest = std::max(longest, now - last);
    last = now;
    if (!f) continue;
    ++frames;
    auto sample = pool.lend(f->data, f->size, std::move(f->lease));
    std::lock_guard lock(mutex);
    queue.emplace_back(now, std::move(sample));
    arrived.notify_one();
  }
  {
    std::lock_guard lock(mutex);
    done = true;
    arrived.notify_one();
  }
  subscriber.join();
  camera.stop();
  ASSERT_EQ(frames, 200);
  // A stall is next()'s 4 s timeout; frames come every 5 ms and a buffer back within a step
  // (a loaded host may add some scheduling delay).
  EXPECT_LT(std::chrono::duration<double>(longest).count(), 2.0)
      << "the capture waited for a buffer that had been let go";
}

}  // namespace
}  // namespace avs::testing
