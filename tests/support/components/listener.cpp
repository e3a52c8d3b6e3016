// test_listener: counts std_msgs/String samples from test_talker and how many arrived as
// the publisher's own buffer (same address: delivered inside the container without a copy).
// Counts sequence gaps too (messages the talker sent that never arrived: a lossy or partitioned
// network, tests/deploy/netfaults.sh), each gap logged, the totals on /diagnostics.
// Writes its counts to `<report_dir>/<name>.yaml` when it stops, for integration tests.
#include <atomic>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "avs/runtime/component.hpp"

namespace avs::testing {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class TestListener final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    return {.type = "test_listener",
            .description = "counts test_talker samples and same-buffer deliveries",
            .parameters = {ParamSpec::string(
                "report_dir", "", "folder for <name>.yaml written on stop, empty = none")},
            .publishes = {},
            .subscribes = {runtime::port<msgs::std_msgs::String>("chatter", "chatter")}};
  }

  explicit TestListener(ComponentContext& ctx)
      : Component(ctx), report_dir_(ctx.param<std::string>("report_dir")) {
    ctx.subscribe<msgs::std_msgs::String>(
        "chatter", [this](runtime::SamplePtr<msgs::std_msgs::String> s) { on_sample(*s); });
  }

  void on_deactivate() override {
    log().info("received ", received_.load(), " messages, ", same_buffer_,
               " as the publisher's buffer, ", missing_.load(), " missing in ", gaps_.load(),
               " gap(s)");
    if (report_dir_.empty()) return;
    const std::string file = report_dir_ + "/" + context().name() + ".yaml";
    std::ofstream out(file);
    out << "received: " << received_.load() << "\nsame_buffer: " << same_buffer_
        << "\nfirst_seq: " << first_seq_ << "\nlast_seq: " << last_seq_
        << "\nmissing: " << missing_.load() << "\n";
    if (!out) log().error("cannot write ", file);
  }

 private:
  void on_sample(const msgs::std_msgs::String& sample) {
    unsigned long long seq = 0;
    void* address = nullptr;
    if (std::sscanf(runtime::get_string(sample.data).data(), "%llu %p", &seq, &address) != 2) {
      log().warn("unexpected payload '", runtime::get_string(sample.data), "'");
      return;
    }
    if (received_ == 0) {
      first_seq_ = seq;
    } else if (seq > last_seq_ + 1) {
      const auto n = seq - last_seq_ - 1;
      missing_ += n;
      ++gaps_;
      log().warn("gap: ", n, " message(s) missing before seq ", seq, " (", missing_.load(),
                 " missing in ", gaps_.load(), " gap(s) so far)");
    } else if (seq <= last_seq_) {
      log().warn("seq ", seq, " after ", last_seq_, ": the talker started again");
    }
    last_seq_ = seq;
    ++received_;
    if (address == static_cast<const void*>(&sample)) ++same_buffer_;
  }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    return {{"received", std::to_string(received_.load())},
            {"missing", std::to_string(missing_.load())},
            {"gaps", std::to_string(gaps_.load())}};
  }

  std::string report_dir_;
  // Read by the diagnostics thread.
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> missing_{0};
  std::atomic<std::uint64_t> gaps_{0};
  std::uint64_t same_buffer_ = 0;
  unsigned long long first_seq_ = 0;
  unsigned long long last_seq_ = 0;
};

AVS_REGISTER_COMPONENT(TestListener);

}  // namespace avs::testing
