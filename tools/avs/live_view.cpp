// --view of `avs demo` and `avs bag play` (live_view.hpp).
#include "live_view.hpp"

#include "avs/runtime/error.hpp"

namespace avs::cli {

void add_live_view_options(Command* cmd, LiveViewFlags& flags, const std::string& what) {
  cmd->add_flag(
      "--view", flags.enabled,
      "serve " + what + " live (avs view: Foxglove WebSocket and the page, docs/view.md)");
  cmd->add_option("--view-port", flags.port, "port of --view (0: any free port)")
      ->capture_default_str()
      ->check_range(0, 65535);
}

std::unique_ptr<view::View> start_live_view(const LiveViewFlags& flags, int domain,
                                            const std::string& partition, const std::string& who,
                                            std::ostream& out, const std::string& page_query) {
  if (!flags.enabled) return nullptr;
  view::ViewOptions o;
  o.domain = domain;
  o.partition = partition;
  o.server.port = static_cast<std::uint16_t>(flags.port);
  o.server.web_root = view::built_page_dir();
  auto live = std::make_unique<view::View>(o);
  live->start();
  out << who << ": live view at http://127.0.0.1:" << live->port() << "/"
      << (page_query.empty() ? "" : "?" + page_query)
      << " (Foxglove: ws://127.0.0.1:" << live->port() << ", domain " << domain << ")";
  if (o.server.web_root.empty()) out << "; NO PAGE: this build had no npm to bundle it";
  out << "\n" << std::flush;
  return live;
}

}  // namespace avs::cli
