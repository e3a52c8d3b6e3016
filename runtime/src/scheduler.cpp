#include "avs/runtime/scheduler.hpp"

#include <algorithm>
#include <chrono>

#include <boost/circular_buffer.hpp>

#include "avs/runtime/error.hpp"

namespace avs::runtime {

/// One queued piece of work: a callback, or a sample delivery (function pointer, context and
/// sample: moved in and out of the queue without an allocation).
struct Scheduler::Lane {
  struct Task {
    Callback callback;
    DeliverFn deliver = nullptr;
    const void* context = nullptr;
    std::shared_ptr<const void> sample;
    std::uint64_t sequence = 0;

    void run() const {
      if (deliver != nullptr) {
        deliver(context, sample, sequence);
      } else {
        callback();
      }
    }
  };

  /// FIFO whose storage only grows (doubling when full): after warm-up a post allocates
  /// nothing, where a std::deque allocates and frees a block every few elements.
  boost::circular_buffer<Task> queue{64};
  bool idle = false;

  void push(Task task) {
    if (queue.full()) queue.set_capacity(2 * queue.capacity());
    queue.push_back(std::move(task));
  }
  Task pop() {
    Task task = std::move(queue.front());
    queue.pop_front();
    return task;
  }
};

namespace {
std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
std::int64_t system_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}
}  // namespace

Scheduler::Scheduler(TimeMode mode, double real_time_factor)
    : mode_(mode), real_time_factor_(real_time_factor) {
  if (mode == TimeMode::sim_realtime && !(real_time_factor > 0)) {
    throw Error("real_time_factor must be > 0, got " + std::to_string(real_time_factor));
  }
}

Scheduler::~Scheduler() = default;

int Scheduler::add_lane() {
  std::lock_guard lock(mutex_);
  lanes_.push_back(std::make_unique<Lane>());
  return static_cast<int>(lanes_.size()) - 1;
}

void Scheduler::post(int lane, Callback fn) {
  Lane::Task task;
  task.callback = std::move(fn);
  {
    std::lock_guard lock(mutex_);
    lanes_.at(static_cast<std::size_t>(lane))->push(std::move(task));
  }
  changed_.notify_all();
}

void Scheduler::post(int lane, DeliverFn deliver, const void* context,
                     std::shared_ptr<const void> sample, std::uint64_t sequence) {
  Lane::Task task;
  task.deliver = deliver;
  task.context = context;
  task.sample = std::move(sample);
  task.sequence = sequence;
  {
    std::lock_guard lock(mutex_);
    lanes_.at(static_cast<std::size_t>(lane))->push(std::move(task));
  }
  changed_.notify_all();
}

std::uint64_t Scheduler::add_timer(int lane, Duration period, Callback fn) {
  if (period.count() <= 0) throw Error("timer period must be positive");
  std::uint64_t id;
  {
    std::lock_guard lock(mutex_);
    id = next_timer_id_++;
    const std::int64_t deadline = (now_locked() + period).ns;
    timers_.emplace(TimerKey{deadline, id},
                    Timer{lane, period, std::make_shared<const Callback>(std::move(fn))});
    timer_deadlines_[id] = deadline;
  }
  changed_.notify_all();
  return id;
}

void Scheduler::cancel_timer(std::uint64_t id) {
  std::lock_guard lock(mutex_);
  auto it = timer_deadlines_.find(id);
  if (it == timer_deadlines_.end()) return;
  timers_.erase(TimerKey{it->second, id});
  timer_deadlines_.erase(it);
}

Time Scheduler::now() const {
  std::lock_guard lock(mutex_);
  return now_locked();
}

Time Scheduler::now_locked() const {
  switch (mode_) {
    case TimeMode::wall:
      return {system_ns()};
    case TimeMode::sim_realtime: {
      if (!steady_start_ns_) return Time{0};  // held until the lanes start
      const double elapsed = static_cast<double>(steady_ns() - *steady_start_ns_);
      return {static_cast<std::int64_t>(elapsed * real_time_factor_)};
    }
    case TimeMode::sim_follower:
    case TimeMode::sim_lockstep:
      return sim_now_;
  }
  return sim_now_;
}

void Scheduler::set_sim_time(Time t) {
  {
    std::lock_guard lock(mutex_);
    if (t <= sim_now_) return;
    sim_now_ = t;
  }
  changed_.notify_all();
}

void Scheduler::stop_at(Time end) {
  {
    std::lock_guard lock(mutex_);
    end_ = end;
  }
  changed_.notify_all();
}

void Scheduler::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
}

bool Scheduler::stopped() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

std::optional<Scheduler::TimerKey> Scheduler::next_timer_locked(int lane) const {
  for (const auto& [key, timer] : timers_) {
    if (timer.lane == lane) return key;
  }
  return std::nullopt;
}

bool Scheduler::all_idle_locked() const {
  for (const auto& lane : lanes_) {
    if (!lane->idle || !lane->queue.empty()) return false;
  }
  return timers_.empty() || timers_.begin()->first.first > sim_now_.ns;
}

void Scheduler::run_lane(int lane_index) {
  std::unique_lock lock(mutex_);
  Lane& lane = *lanes_.at(static_cast<std::size_t>(lane_index));
  // The first lane to start anchors the paced clock: timers made before (at activation) fall
  // due one period after it, as they would had the clock started then.
  if (mode_ == TimeMode::sim_realtime && !steady_start_ns_) steady_start_ns_ = steady_ns();
  while (!stopping_) {
    if (end_ && now_locked() >= *end_) {
      stopping_ = true;
      changed_.notify_all();
      break;
    }
    if (!lane.queue.empty()) {
      {
        const Lane::Task task = lane.pop();
        lock.unlock();
        task.run();
      }  // the task and its sample released before the lock is taken again
      lock.lock();
      continue;
    }
    const auto next = next_timer_locked(lane_index);
    const Time now = now_locked();
    if (next && next->first <= now.ns) {
      // The timer's node re-keyed and put back: no allocation per tick.
      auto node = timers_.extract(*next);
      const Timer& timer = node.mapped();
      // Next deadline on the period grid; in wall time, skip slots already missed.
      std::int64_t deadline = next->first + timer.period.count();
      if (deadline <= now.ns && mode_ != TimeMode::sim_lockstep) {
        const std::int64_t missed = (now.ns - deadline) / timer.period.count() + 1;
        deadline += missed * timer.period.count();
      }
      // A reference, not a copy of the function: the timer may be cancelled while fn runs.
      const std::shared_ptr<const Callback> fn = timer.fn;
      const std::uint64_t id = next->second;
      node.key() = TimerKey{deadline, id};
      timers_.insert(std::move(node));
      timer_deadlines_[id] = deadline;
      lock.unlock();
      (*fn)();
      lock.lock();
      continue;
    }
    wait_locked(lock, lane_index);
  }
}

void Scheduler::wait_locked(std::unique_lock<std::mutex>& lock, int lane_index) {
  Lane& lane = *lanes_.at(static_cast<std::size_t>(lane_index));
  lane.idle = true;
  const auto next = next_timer_locked(lane_index);
  switch (mode_) {
    case TimeMode::wall: {
      if (next) {
        const auto deadline = std::chrono::system_clock::time_point(
            std::chrono::duration_cast<std::chrono::system_clock::duration>(
                std::chrono::nanoseconds(next->first)));
        changed_.wait_until(lock, deadline);
      } else {
        changed_.wait_for(lock, std::chrono::milliseconds(100));
      }
      break;
    }
    case TimeMode::sim_realtime: {
      const std::int64_t target =
          next ? next->first : (now_locked() + std::chrono::milliseconds(1)).ns;
      const auto wake = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(
          *steady_start_ns_ +
          static_cast<std::int64_t>(static_cast<double>(target) / real_time_factor_)));
      changed_.wait_until(lock, wake);
      const Time t = now_locked();
      if (time_advanced_) {
        lock.unlock();
        time_advanced_(t);
        lock.lock();
      }
      break;
    }
    case TimeMode::sim_follower:
      changed_.wait_for(lock, std::chrono::milliseconds(100));
      break;
    case TimeMode::sim_lockstep: {
      if (all_idle_locked() && !timers_.empty() && before_advance_) {
        lane.idle = false;  // no other lane advances meanwhile
        lock.unlock();
        before_advance_();
        lock.lock();
        lane.idle = true;
        // A callback queued meanwhile (this lane's too) runs first, without a wait; a stop
        // requested meanwhile ends the run where it is.
        if (!all_idle_locked() || stopping_) break;
      }
      if (all_idle_locked() && !timers_.empty()) {
        // Every lane is idle and nothing is due: jump to the earliest deadline.
        Time t{timers_.begin()->first.first};
        if (end_ && t > *end_) t = *end_;
        sim_now_ = t;
        changed_.notify_all();
        if (time_advanced_) {
          lane.idle = false;
          lock.unlock();
          time_advanced_(t);
          lock.lock();
        }
      } else {
        changed_.wait_for(lock, std::chrono::milliseconds(100));
      }
      break;
    }
  }
  lane.idle = false;
}

}  // namespace avs::runtime
