// view: the live view (libs/view: Foxglove WebSocket server, the page at http://HOST:PORT/)
// as a component, so that a graph serves itself without a separate `avs view` process. It has
// no ports: like `avs view` it discovers every topic of the graph's DDS domain and partition
// with a participant of its own and forwards the CDR bytes as DDS delivers them. It takes no
// part in the container's schedule (its readers are best effort, its threads its own), so a
// lockstep graph runs the same with it or without it.
#include <cstdint>
#include <memory>
#include <string>

#include "avs/runtime/component.hpp"
#include "avs/runtime/error.hpp"
#include "avs/view/view.hpp"

namespace avs::view {

using runtime::ComponentContext;
using runtime::ComponentSpec;
using runtime::ParamSpec;

class ViewComponent final : public runtime::Component {
 public:
  static ComponentSpec spec() {
    const ServerOptions server_defaults;
    const SessionLimits limit_defaults;
    return {
        .type = "view",
        .description = "live view of the graph: Foxglove WebSocket server (" +
                       std::string(kSubprotocol) + ") and the page (docs/view.md)",
        .parameters = {
            ParamSpec::integer("port", server_defaults.port, 0, 65535, "",
                               "TCP port (0: any free port, logged at activation)"),
            ParamSpec::string("address", server_defaults.address,
                              "address to listen on (0.0.0.0: every interface)"),
            ParamSpec::real("image_max_rate_hz", 0, 0, 1e6, "Hz",
                            "default per-client limit for image and point cloud topics (0: "
                            "none); a client may set its own with ?max_rate_hz=N"),
            ParamSpec::integer("queue_depth", static_cast<std::int64_t>(limit_defaults.queue_depth),
                               1, 1e6, "",
                               "messages waiting per client and subscription (the oldest is "
                               "dropped and counted when a slow client lets it fill)"),
            ParamSpec::string("web_root", "",
                              "folder of the page served at / (empty: the one this build "
                              "bundled)")}};
  }

  explicit ViewComponent(ComponentContext& ctx) : Component(ctx) {
    ViewOptions o;
    o.domain = ctx.dds_domain();
    o.partition = ctx.dds_partition();
    o.server.address = ctx.param<std::string>("address");
    o.server.port = static_cast<std::uint16_t>(ctx.param<std::int64_t>("port"));
    o.server.client_defaults.max_rate_hz = ctx.param<double>("image_max_rate_hz");
    o.server.limits.queue_depth = static_cast<std::size_t>(ctx.param<std::int64_t>("queue_depth"));
    const auto web_root = ctx.param<std::string>("web_root");
    o.server.web_root = web_root.empty() ? built_page_dir() : std::filesystem::path(web_root);
    address_ = o.server.address;
    web_root_ = o.server.web_root.string();
    view_ = std::make_unique<View>(std::move(o));
  }

  void on_activate() override {
    view_->start();  // throws (the component fails, with the reason) when the port is taken
    const auto port = std::to_string(view_->port());
    log().info("Foxglove WebSocket server on ws://", address_, ":", port, " (domain ",
               context().dds_domain(), ")");
    if (web_root_.empty()) {
      log().warn("NO PAGE at http://", address_, ":", port,
                 "/: this build had no npm to bundle it");
    } else {
      log().info("page at http://", address_, ":", port, "/ (from ", web_root_, ")");
    }
  }

  void on_deactivate() override { view_->stop(); }

  std::vector<std::pair<std::string, std::string>> diagnostic_values() const override {
    const ServerStats s = view_->stats();
    if (!s.valid) return {{"port", std::to_string(view_->port())}};
    return {{"port", std::to_string(view_->port())},
            {"clients", std::to_string(s.clients.size())},
            {"channels", std::to_string(s.channels.size())}};
  }

 private:
  std::string address_;
  std::string web_root_;
  std::unique_ptr<View> view_;
};

AVS_REGISTER_COMPONENT(ViewComponent);

}  // namespace avs::view
