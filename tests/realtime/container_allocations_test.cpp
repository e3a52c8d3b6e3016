// Issue 16 section 3, in a container: a sample published by one component and delivered to
// another on the same lane (the intra-process path every frame takes: publish, the lane's queue,
// the subscription's callback), and a timer's tick, allocate nothing after warm-up. The source
// reuses one sample, as the components' sample pools do, so what is counted is the container's.
#include <atomic>
#include <memory>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "avs/runtime/component.hpp"
#include "avs/runtime/sample.hpp"
#include "avs/testing/lockstep_graph.hpp"

namespace avs::testing {
namespace {

constexpr int kWarmUpTicks = 100;
constexpr int kCountedTicks = 1000;

/// Counting runs from the start of a tick to the end of the sink's callback for the sample the
/// tick published: the timer, publish, the queue and the delivery, and nothing else the lane
/// does (the container's 1 Hz diagnostics, the lockstep clock's /clock).
std::atomic<long> g_deliveries{0};

class AllocSource final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_source",
            .description =
                "publishes one reused std_msgs/Float64 every 1 ms, counting "
                "allocations from its tick to the sink's delivery",
            .parameters = {},
            .publishes = {runtime::port<msgs::std_msgs::Float64>("out", "alloc_probe")},
            .subscribes = {}};
  }
  explicit AllocSource(runtime::ComponentContext& ctx)
      : Component(ctx),
        out_(ctx.publisher<msgs::std_msgs::Float64>("out")),
        sample_(runtime::make_sample<msgs::std_msgs::Float64>()) {}
  void on_activate() override {
    timer_ = context().create_timer(std::chrono::milliseconds(1), [this] { tick(); });
  }

  long ticks = 0;
  long counted = -1;  ///< allocations over the counted ticks (-1: not reached)

 private:
  void tick() {
    ++ticks;
    if (ticks == kWarmUpTicks) reset_counted_allocations();
    if (ticks == kWarmUpTicks + kCountedTicks) counted = counted_allocations();
    const bool counting = ticks >= kWarmUpTicks && ticks < kWarmUpTicks + kCountedTicks;
    count_allocations_on_this_thread(counting);
    sample_->data = static_cast<double>(ticks);
    out_.publish(sample_);
  }

  runtime::Publisher<msgs::std_msgs::Float64> out_;
  std::shared_ptr<msgs::std_msgs::Float64> sample_;
  runtime::TimerId timer_{};
};

class AllocSink final : public runtime::Component {
 public:
  static runtime::ComponentSpec spec() {
    return {.type = "test_alloc_sink",
            .description = "counts the samples it gets and ends the allocation count",
            .parameters = {},
            .publishes = {},
            .subscribes = {runtime::port<msgs::std_msgs::Float64>("in", "alloc_probe")}};
  }
  explicit AllocSink(runtime::ComponentContext& ctx) : Component(ctx) {
    ctx.subscribe<msgs::std_msgs::Float64>("in", [](runtime::SamplePtr<msgs::std_msgs::Float64>) {
      g_deliveries.fetch_add(1);
      count_allocations_on_this_thread(false);
    });
  }
};

AVS_REGISTER_COMPONENT(AllocSource);
AVS_REGISTER_COMPONENT(AllocSink);

TEST(ContainerAllocations, PublishDeliverAndTimerTicksAllocateNothingAfterWarmUp) {
  const ContainerRun run = run_lockstep_container(
      {"{type: test_alloc_source, name: source}", "{type: test_alloc_sink, name: sink}"},
      (kWarmUpTicks + kCountedTicks + 50) * 1e-3);
  ASSERT_EQ(run.status, 0);
  const auto* source = run.find<AllocSource>("source");
  ASSERT_NE(source, nullptr);
  ASSERT_GE(source->ticks, kWarmUpTicks + kCountedTicks);
  EXPECT_GE(g_deliveries.load(), kWarmUpTicks + kCountedTicks);  // the path really ran
  EXPECT_EQ(source->counted, 0) << "allocations over " << kCountedTicks
                                << " ticks, each a publish and a delivery";
}

}  // namespace
}  // namespace avs::testing
