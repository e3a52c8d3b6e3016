// `avs view`: the Foxglove WebSocket server fed from the DDS graph. Every topic that has a
// publisher (seen through DDS discovery, like `avs topic list`) and a type this build knows
// is advertised with its ros2msg schema and encoding `cdr`; a channel disappears when its
// last publisher does. A DDS reader exists only while some client subscribes, and it hands
// the serialised samples on exactly as received (no deserialise/serialise). Per-client
// counters (sent, dropped, throttled, rejected) go to /diagnostics once a second.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "avs/view/server.hpp"

namespace avs::view {

struct ViewOptions {
  ServerOptions server;
  int domain = 0;
  std::string partition;              ///< DDS partition of the readers (empty: the default one)
  double diagnostics_period_s = 1.0;  ///< 0: no /diagnostics
};

class View {
 public:
  /// Creates the DDS participants; throws runtime::Error on DDS failures.
  explicit View(ViewOptions options);
  ~View();
  View(const View&) = delete;
  View& operator=(const View&) = delete;

  /// Starts the server (throws when the port cannot be opened) and the DDS thread.
  void start();
  void stop();
  std::uint16_t port() const;
  ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The page bundled by this build (libs/view/page), or "" when the build had no npm.
std::filesystem::path built_page_dir();

/// True for the types a client's max_rate_hz thins (images, point clouds, pattern frames).
bool is_image_type(const std::string& ros_type);

}  // namespace avs::view
