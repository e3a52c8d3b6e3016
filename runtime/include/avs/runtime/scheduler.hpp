// Runs the callbacks of a container's components on one or more threads ("lanes") and
// owns the container's notion of time: wall time, or simulated time that is either
// followed (from /clock), advanced in lockstep (as fast as possible, only when every lane
// is idle, so results depend only on inputs), or advanced at a real-time factor.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "avs/runtime/time.hpp"

namespace avs::runtime {

enum class TimeMode { wall, sim_follower, sim_lockstep, sim_realtime };

class Scheduler {
 public:
  using Callback = std::function<void()>;
  /// A sample delivery: called on the lane as deliver(context, sample, sequence).
  using DeliverFn = void (*)(const void* context, const std::shared_ptr<const void>& sample,
                             std::uint64_t sequence);

  explicit Scheduler(TimeMode mode, double real_time_factor = 1.0);
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  /// Adds a lane (one thread's queue) and returns its index. Call before run_lane().
  int add_lane();

  /// Queues `fn` on `lane`, FIFO. Thread-safe.
  void post(int lane, Callback fn);
  /// Queues a sample delivery on `lane`, FIFO with the callbacks. Allocates nothing once the
  /// lane's queue has grown to its working size (issue 16 section 3: a sample posted per frame
  /// must not cost a heap allocation, as a lambda in a std::function does); `context` must
  /// outlive the delivery.
  void post(int lane, DeliverFn deliver, const void* context, std::shared_ptr<const void> sample,
            std::uint64_t sequence);

  /// Calls `fn` on `lane` every `period`, first at now() + period. Thread-safe.
  std::uint64_t add_timer(int lane, Duration period, Callback fn);
  void cancel_timer(std::uint64_t id);

  /// sim_realtime: simulated time stands at 0 until the first lane starts (run_lane), then
  /// advances at the real-time factor from there: building and activating the components
  /// (seconds for a model's distance grid, more under a sanitizer) is not simulated time, so
  /// the loop does not start behind and fire its first timers in a burst to catch up.
  Time now() const;
  TimeMode mode() const { return mode_; }

  /// sim_follower: time received on /clock. Never goes backwards.
  void set_sim_time(Time t);

  /// Stops every lane once `end` is reached (sim or wall time).
  void stop_at(Time end);

  /// Called (outside the lock, on a lane thread) each time simulated time advances in
  /// lockstep or realtime mode; the container publishes /clock from it.
  void on_time_advanced(std::function<void(Time)> fn) { time_advanced_ = std::move(fn); }

  /// Lockstep: called (outside the lock, on a lane thread, no lane running a callback) each
  /// time every lane is idle and time is about to advance; time advances once it returns,
  /// unless a callback was queued meanwhile (that runs first). The container waits there for
  /// recorders' acknowledgements.
  void before_time_advance(std::function<void()> fn) { before_advance_ = std::move(fn); }

  /// Thread body: runs `lane`'s callbacks and timers until stop().
  void run_lane(int lane);
  void stop();
  bool stopped() const;

 private:
  struct Timer {
    int lane;
    Duration period;
    /// Shared: the lane runs its own reference without a copy of the function, and a timer
    /// cancelled while its callback runs keeps that callback alive until it returns.
    std::shared_ptr<const Callback> fn;
  };
  struct Lane;  // scheduler.cpp: a queue that keeps its storage
  using TimerKey = std::pair<std::int64_t, std::uint64_t>;  // (deadline ns, id)

  Time now_locked() const;
  bool all_idle_locked() const;
  std::optional<TimerKey> next_timer_locked(int lane) const;
  void wait_locked(std::unique_lock<std::mutex>& lock, int lane);

  const TimeMode mode_;
  const double real_time_factor_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::unique_ptr<Lane>> lanes_;
  std::map<TimerKey, Timer> timers_;
  std::map<std::uint64_t, std::int64_t> timer_deadlines_;  // id -> deadline, for cancel
  std::uint64_t next_timer_id_ = 1;
  Time sim_now_{0};
  std::optional<std::int64_t> steady_start_ns_;  // sim_realtime: wall origin, from run_lane
  std::optional<Time> end_;
  bool stopping_ = false;
  std::function<void(Time)> time_advanced_;
  std::function<void()> before_advance_;
};

}  // namespace avs::runtime
