// test_talker: publishes std_msgs/String "<seq> <address of this sample>" at a fixed rate,
// and its sequence number as std_msgs/Float64 on a second port (a second type for tests).
// Carrying its own address lets a listener prove it got the very same buffer (no copy).
#include <chrono>
#include <cstdio>
#include <thread>

#include "avs/runtime/component.hpp"

namespace avs::testing {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class TestTalker final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {
        .type = "test_talker",
        .description = "publishes '<seq> <sample address>' strings at rate_hz",
        .parameters = {ParamSpec::real("rate_hz", 100.0, 0.001, 100000.0, "Hz", "publishing rate"),
                       ParamSpec::integer("count", 0, 0, std::nullopt, "",
                                          "messages to send, 0 = until stopped"),
                       ParamSpec::integer("fail_after", 0, 0, std::nullopt, "",
                                          "throw after this many messages (tests failure "
                                          "reporting and respawn), 0 = never"),
                       ParamSpec::real("work_ms", 0.0, 0.0, 10000.0, "ms",
                                       "sleep this long in every tick (a stage slowed on "
                                       "purpose: the timer cannot keep rate_hz)"),
                       ParamSpec::integer("burst", 1, 1, 10000, "",
                                          "messages published back to back in every tick (an "
                                          "input faster than its subscribers)")},
        .publishes = {runtime::port<msgs::std_msgs::String>("chatter", "chatter"),
                      runtime::port<msgs::std_msgs::Float64>("count", "talker_count")},
        .subscribes = {}};
  }

  explicit TestTalker(ComponentContext& ctx)
      : Component(ctx),
        chatter_(ctx.publisher<msgs::std_msgs::String>("chatter")),
        count_topic_(ctx.publisher<msgs::std_msgs::Float64>("count")),
        period_(static_cast<std::int64_t>(1e9 / ctx.param<double>("rate_hz"))),
        count_(ctx.param<std::int64_t>("count")),
        fail_after_(ctx.param<std::int64_t>("fail_after")),
        work_(std::chrono::duration<double, std::milli>(ctx.param<double>("work_ms"))),
        burst_(ctx.param<std::int64_t>("burst")) {}

  void on_activate() override {
    timer_ = context().create_timer(period_, [this] { tick(); });
  }
  void on_deactivate() override { log().info("published ", seq_, " messages"); }

 private:
  void tick() {
    if (work_.count() > 0) std::this_thread::sleep_for(work_);
    for (std::int64_t i = 0; i < burst_; ++i) publish_one();
  }

  void publish_one() {
    if (count_ > 0 && seq_ >= static_cast<std::uint64_t>(count_)) return;
    if (fail_after_ > 0 && seq_ >= static_cast<std::uint64_t>(fail_after_)) {
      throw std::runtime_error("failing on purpose after " + std::to_string(seq_) + " messages");
    }
    auto sample = runtime::make_sample<msgs::std_msgs::String>();
    char text[64];
    std::snprintf(text, sizeof text, "%llu %p", static_cast<unsigned long long>(seq_),
                  static_cast<const void*>(sample.get()));
    runtime::set_string(sample->data, text);
    chatter_.publish(std::move(sample));
    auto count = runtime::make_sample<msgs::std_msgs::Float64>();
    count->data = static_cast<double>(seq_);
    count_topic_.publish(std::move(count));
    ++seq_;
  }

  runtime::Publisher<msgs::std_msgs::String> chatter_;
  runtime::Publisher<msgs::std_msgs::Float64> count_topic_;
  runtime::Duration period_;
  std::int64_t count_;
  std::int64_t fail_after_;
  std::chrono::duration<double, std::milli> work_;
  std::int64_t burst_;
  std::uint64_t seq_ = 0;
  runtime::TimerId timer_ = 0;
};

AVS_REGISTER_COMPONENT(TestTalker);

}  // namespace avs::testing
