#include "avs/runtime/scheduler.hpp"

#include <gtest/gtest.h>

#include "avs/runtime/error.hpp"

#include <thread>
#include <vector>

namespace avs::runtime {
namespace {

using std::chrono::milliseconds;

// Lockstep: timers fire in deadline order at exactly their deadlines, however fast the
// machine is, and time stops at the end.
TEST(SchedulerTest, LockstepFiresTimersInDeadlineOrderAtTheirDeadlines) {
  Scheduler scheduler(TimeMode::sim_lockstep);
  const int lane = scheduler.add_lane();
  std::vector<std::pair<char, std::int64_t>> fired;
  scheduler.add_timer(lane, milliseconds(2), [&] { fired.push_back({'a', scheduler.now().ns}); });
  scheduler.add_timer(lane, milliseconds(3), [&] { fired.push_back({'b', scheduler.now().ns}); });
  scheduler.stop_at(Time{7'000'000});
  scheduler.run_lane(lane);

  const std::vector<std::pair<char, std::int64_t>> expected = {
      {'a', 2'000'000}, {'b', 3'000'000}, {'a', 4'000'000}, {'a', 6'000'000}, {'b', 6'000'000}};
  EXPECT_EQ(fired, expected);
  EXPECT_EQ(scheduler.now().ns, 7'000'000);
}

// Lockstep with two lanes: time advances only when both are idle, so work posted from one
// lane to the other is done before the clock moves on.
TEST(SchedulerTest, LockstepWaitsForEveryLaneBeforeAdvancing) {
  Scheduler scheduler(TimeMode::sim_lockstep);
  const int producer = scheduler.add_lane();
  const int consumer = scheduler.add_lane();
  std::vector<std::int64_t> handled_at;  // only touched on the consumer lane
  std::vector<Time> advances;
  scheduler.on_time_advanced([&](Time t) { advances.push_back(t); });
  scheduler.add_timer(producer, milliseconds(1), [&] {
    const Time sent = scheduler.now();
    scheduler.post(consumer, [&, sent] {
      std::this_thread::sleep_for(std::chrono::microseconds(200));  // slow consumer
      handled_at.push_back(scheduler.now().ns - sent.ns);
    });
  });
  scheduler.stop_at(Time{50'000'000});
  std::thread t([&] { scheduler.run_lane(consumer); });
  scheduler.run_lane(producer);
  t.join();

  ASSERT_EQ(handled_at.size(), 49u);
  for (std::int64_t lag : handled_at) EXPECT_EQ(lag, 0) << "time moved while the consumer was busy";
}

// Paced simulated time starts with the lanes, not with the scheduler: what happens between
// (the container building and activating its components, seconds under a sanitizer) is not
// simulated time. Before the fix the clock ran from construction, so here the whole run
// (0.5 s) had passed before the lane started, and the timer never fired.
TEST(SchedulerTest, RealtimeClockStartsWithTheLanesNotWithTheScheduler) {
  Scheduler scheduler(TimeMode::sim_realtime, 1.0);
  const int lane = scheduler.add_lane();
  std::vector<std::int64_t> fired_ns;
  scheduler.add_timer(lane, milliseconds(100), [&] { fired_ns.push_back(scheduler.now().ns); });
  scheduler.stop_at(Time{500'000'000});
  std::this_thread::sleep_for(milliseconds(600));  // "start-up"
  EXPECT_EQ(scheduler.now().ns, 0) << "the clock ran before any lane did";

  scheduler.run_lane(lane);
  ASSERT_FALSE(fired_ns.empty());
  EXPECT_GE(fired_ns.front(), 100'000'000);  // one period after the lanes started
  EXPECT_GE(scheduler.now().ns, 500'000'000);
}

TEST(SchedulerTest, PostedCallbacksRunInOrder) {
  Scheduler scheduler(TimeMode::sim_lockstep);
  const int lane = scheduler.add_lane();
  std::vector<int> order;
  for (int i = 0; i < 5; ++i) scheduler.post(lane, [&, i] { order.push_back(i); });
  scheduler.post(lane, [&] { scheduler.stop(); });
  scheduler.run_lane(lane);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(SchedulerTest, CancelledTimerNeverFires) {
  Scheduler scheduler(TimeMode::sim_lockstep);
  const int lane = scheduler.add_lane();
  int a = 0, b = 0;
  const auto id = scheduler.add_timer(lane, milliseconds(1), [&] { ++a; });
  scheduler.add_timer(lane, milliseconds(1), [&] {
    ++b;
    scheduler.cancel_timer(id);
  });
  scheduler.stop_at(Time{10'000'000});
  scheduler.run_lane(lane);
  EXPECT_EQ(a, 1);  // fired once at 1 ms (before b cancelled it)
  EXPECT_EQ(b, 9);
}

TEST(SchedulerTest, FollowerTimeOnlyMovesForward) {
  Scheduler scheduler(TimeMode::sim_follower);
  scheduler.set_sim_time(Time{5});
  scheduler.set_sim_time(Time{3});
  EXPECT_EQ(scheduler.now().ns, 5);
}

TEST(SchedulerTest, RejectsNonPositivePeriod) {
  Scheduler scheduler(TimeMode::wall);
  const int lane = scheduler.add_lane();
  EXPECT_THROW(scheduler.add_timer(lane, milliseconds(0), [] {}), Error);
}

}  // namespace
}  // namespace avs::runtime
