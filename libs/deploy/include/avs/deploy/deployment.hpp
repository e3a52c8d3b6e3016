// A deployment: which host runs which containers of a graph, and how the hosts reach each
// other over DDS. Loaded from YAML by load_deployment() (format: docs/deploy.md), turned into
// one Cyclone DDS configuration per host (and per participant when security is on) by
// cyclone_config().
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "avs/graph/graph.hpp"

namespace avs::deploy {

struct Host {
  std::string name;       ///< letters, digits, '_' and '-'
  std::string address;    ///< IPv4 address of this host on the DDS network; may be empty
  std::string interface;  ///< network interface name; may be empty (then `address` picks it)
  std::vector<std::string> containers;  ///< graph containers this host runs
  graph::SourceLocation where;
};

struct Discovery {
  bool multicast = true;           ///< false: unicast SPDP to every other host's address (peers)
  double lease_duration_s = 10.0;  ///< a silent participant is dropped after this
  int max_participants_per_host = 20;  ///< participant indices probed per peer (unicast)
};

/// Sizing for the largest stream (256 KiB images at 1 kHz by default).
struct Transport {
  std::uint64_t image_bytes = 262144;
  double image_rate_hz = 1000.0;
  double buffer_ms = 32.0;                 ///< writer cache / socket buffers hold this much
  std::uint64_t max_message_size = 65500;  ///< UDP payload per RTPS message
  std::uint64_t fragment_size = 0;         ///< 0: Cyclone's default (1344 B, fits a 1500 MTU)
  /// Cyclone's receive-buffer block (Sizing/ReceiveBufferSize): each receive thread carves the
  /// messages it keeps out of one such block until it is full, then takes a new one. 0: its
  /// default, 1 MiB; otherwise at least kMinReceiveBufferBytes.
  std::uint64_t receive_buffer_bytes = 0;
  /// Cyclone silently raises a block smaller than its largest message chunk
  /// (ReceiveBufferChunkSize, 128 KiB) to that size, and a block of one chunk holds a single
  /// kept message: smaller values are refused rather than changed behind the user's back.
  static constexpr std::uint64_t kMinReceiveBufferBytes = 256 * 1024;
  /// Bytes one `buffer_ms` window of images needs: writer history (WhcHigh) and the
  /// receiver's socket buffer are sized to it.
  std::uint64_t window_bytes() const;
};

struct Security {
  bool enabled = false;
  std::string dir;  ///< output of `avs security init`, absolute
};

struct SharedMemory {
  bool enabled = false;
};

struct Deployment {
  std::string file;                               ///< the deployment YAML
  std::string graph_file;                         ///< resolved against the deployment's folder
  std::map<std::string, std::string> graph_args;  ///< `args:` of the deployment, as text
  int domain_id = 0;
  std::string partition;  ///< DDS partition of every reader and writer; empty: default
  Discovery discovery;
  Transport transport;
  Security security;
  SharedMemory shared_memory;
  std::vector<Host> hosts;
  graph::Graph graph;  ///< the loaded graph (with the deployment's args)

  const Host* find_host(const std::string& name) const;
  /// The host running `container`, or nullptr.
  const Host* host_of(const std::string& container) const;
  std::vector<std::string> host_names() const;
};

struct LoadResult {
  std::optional<Deployment> deployment;
  std::vector<graph::Diagnostic> errors;  ///< deployment file first, then the graph's
  bool ok() const { return deployment.has_value() && errors.empty(); }
};

/// True when `file` is a deployment (a YAML mapping with a `hosts` key) rather than a graph.
bool is_deployment_file(const std::string& file);

/// Loads and validates a deployment and the graph it names. `overrides` (NAME:=VALUE from the
/// command line) replace the deployment's graph `args`. Every error is collected, one per
/// file:line:column. `check_security_files`: with security enabled, the security folder must
/// hold a CA (false only for `avs security init`, which creates it).
LoadResult load_deployment(const std::string& file,
                           const std::map<std::string, std::string>& overrides,
                           bool check_security_files = true);

/// Cyclone DDS XML (a complete <CycloneDDS> document) for participants on `host`: network
/// interface, multicast or unicast peers with participant indices, lease duration, writer
/// cache and socket buffers, shared memory and, when security is on, the identity of
/// `participant` (a container name, or "observer" for tools) from the security folder.
std::string cyclone_config(const Deployment& deployment, const Host& host,
                           const std::string& participant);

/// Files of one participant's identity in a security folder (see `avs security init`).
struct IdentityFiles {
  std::string ca_cert, cert, key, governance, permissions;
};
IdentityFiles identity_files(const std::string& security_dir, const std::string& participant);

/// The DDS-security plugin folder of Debian's Cyclone build, or "" when absent.
std::string security_plugin_dir();

}  // namespace avs::deploy
