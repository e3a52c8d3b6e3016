// avs view: the Foxglove WebSocket server for a running graph (libs/view, docs/view.md).
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <thread>

#include "avs/runtime/dds.hpp"
#include "avs/view/view.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace {

struct ViewArgs {
  std::string address = "127.0.0.1";
  unsigned port = 8765;
  int domain = 0;  // add_domain_option
  double image_max_rate_hz = 0;
  unsigned long queue_depth = 8;
  double duration_s = 0;
  std::string web_root = view::built_page_dir().string();
};

void run_view(const ViewArgs& a) {
  if (a.port > 65535) throw runtime::Error("avs view: --port must be in [0, 65535]");
  if (a.queue_depth == 0) throw runtime::Error("avs view: --queue-depth must be at least 1");
  view::ViewOptions o;
  o.domain = a.domain;
  o.partition = environment_partition();
  o.server.address = a.address;
  o.server.port = static_cast<std::uint16_t>(a.port);
  o.server.client_defaults.max_rate_hz = a.image_max_rate_hz;
  o.server.limits.queue_depth = a.queue_depth;
  o.server.web_root = a.web_root;
  view::View v(o);
  v.start();
  std::printf("avs view: Foxglove WebSocket server on ws://%s:%u (domain %d, subprotocol %s)\n",
              a.address.c_str(), static_cast<unsigned>(v.port()), a.domain,
              std::string(view::kSubprotocol).c_str());
  if (a.web_root.empty()) {
    std::printf("avs view: NO PAGE at http://%s:%u/: this build had no npm to bundle it\n",
                a.address.c_str(), static_cast<unsigned>(v.port()));
  } else {
    std::printf("avs view: page at http://%s:%u/ (from %s)\n", a.address.c_str(),
                static_cast<unsigned>(v.port()), a.web_root.c_str());
  }
  std::fflush(stdout);
  stop_on_interrupt();
  const auto start = std::chrono::steady_clock::now();
  while (!stop_requested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (a.duration_s > 0 &&
        std::chrono::steady_clock::now() - start > std::chrono::duration<double>(a.duration_s)) {
      break;
    }
  }
  v.stop();
}

}  // namespace

void add_view_command(Command& app) {
  static ViewArgs a;
  auto* cmd = app.add_subcommand(
      "view",
      "Foxglove WebSocket server (foxglove.websocket.v1) for the topics of a running graph");
  cmd->add_option("--port", a.port, "TCP port (0: any free port, printed at start)")
      ->capture_default_str()
      ->check_range(0, 65535);
  cmd->add_option("--address", a.address, "address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  add_domain_option(cmd, a.domain);
  cmd->add_option("--image-max-rate-hz", a.image_max_rate_hz,
                  "default per-client limit for image and point cloud topics (0: none); a "
                  "client may set its own with ws://HOST:PORT/?max_rate_hz=N")
      ->check_range(0, 1e6);
  cmd->add_option("--queue-depth", a.queue_depth,
                  "messages waiting per client and subscription; the oldest is dropped (and "
                  "counted on /diagnostics) when a slow client lets it fill")
      ->capture_default_str()
      ->check_range(1, 1e6);
  cmd->add_option("--web-root", a.web_root,
                  "folder of the page served at / (default: the one this build bundled)")
      ->capture_default_str();
  cmd->add_option("--duration", a.duration_s, "stop after this many seconds (0: until Ctrl-C)")
      ->check_range(0, 1e9);
  cmd->footer(
      "Every DDS topic with a publisher and a type this build knows is advertised with its "
      "ros2msg schema and encoding cdr; messages are forwarded as received from DDS. "
      "http://HOST:PORT/ serves the live page (depth map, pose, pan/tilt, diagnostics). "
      "See docs/view.md.");
  cmd->callback([] { run_view(a); });
}

AVS_REGISTER_COMMAND(add_view_command)

}  // namespace avs::cli
