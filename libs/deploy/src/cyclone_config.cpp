// cyclone_config(): the Cyclone DDS XML for one host (and participant) of a deployment.
// Recipes and measurements behind every element: ../shared/reference/dds-cyclone-notes.md.
#include <algorithm>
#include <filesystem>
#include <sstream>

#include "avs/deploy/deployment.hpp"
#include "avs/runtime/text.hpp"

namespace avs::deploy {
namespace {

std::string file_uri(const std::string& path) {
  return "file:" + runtime::escape_markup(path);
}

}  // namespace

IdentityFiles identity_files(const std::string& dir, const std::string& participant) {
  const std::filesystem::path d(dir);
  const auto id = d / "identities" / participant;
  return {(d / "ca_cert.pem").string(), (id / "cert.pem").string(), (id / "key.pem").string(),
          (d / "governance.p7s").string(), (d / "permissions.p7s").string()};
}

std::string security_plugin_dir() {
  for (const char* dir : {"/usr/lib/x86_64-linux-gnu/libddsc0debian",
                          "/usr/lib/aarch64-linux-gnu/libddsc0debian", "/usr/lib/libddsc0debian"}) {
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::path(dir) / "libdds_security_auth.so", ec)) {
      return dir;
    }
  }
  return "";
}

std::string cyclone_config(const Deployment& d, const Host& host, const std::string& participant) {
  std::ostringstream x;
  x << "<CycloneDDS><Domain id=\"any\">";

  // Network: the host's interface (by name, or the one holding its address); multicast
  // discovery and data, or none at all.
  x << "<General>";
  if (!host.interface.empty() || !host.address.empty()) {
    x << "<Interfaces><NetworkInterface ";
    if (!host.interface.empty()) {
      x << "name=\"" << runtime::escape_markup(host.interface) << "\"";
    } else {
      x << "address=\"" << runtime::escape_markup(host.address) << "\"";
    }
    x << "/></Interfaces>";
  }
  x << "<AllowMulticast>" << (d.discovery.multicast ? "true" : "false") << "</AllowMulticast>";
  // Larger RTPS messages cut per-image overhead (256 KiB in 5 messages instead of 196).
  x << "<MaxMessageSize>" << d.transport.max_message_size << "B</MaxMessageSize>";
  if (d.transport.fragment_size > 0) {
    x << "<FragmentSize>" << d.transport.fragment_size << "B</FragmentSize>";
  }
  x << "</General>";

  // Discovery: fixed participant indices, so unicast SPDP to a peer reaches known ports
  // (7410 + 2 i); with ParticipantIndex none the ports are random and unicast-only
  // discovery never completes (notes, section 4).
  x << "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
    << "<MaxAutoParticipantIndex>" << d.discovery.max_participants_per_host - 1
    << "</MaxAutoParticipantIndex>";
  if (!d.discovery.multicast) {
    std::vector<std::string> peers;
    for (const auto& h : d.hosts) {
      if (!h.address.empty()) peers.push_back(h.address);  // own address too: local containers
    }
    if (!peers.empty()) {
      x << "<Peers>";
      for (const auto& p : peers) x << "<Peer address=\"" << runtime::escape_markup(p) << "\"/>";
      x << "</Peers>";
    }
  }
  char lease[32];
  std::snprintf(lease, sizeof lease, "%gs", d.discovery.lease_duration_s);
  x << "<LeaseDuration>" << lease << "</LeaseDuration></Discovery>";

  // Buffers: the writer history cache holds `buffer_ms` of images unacknowledged (the default
  // 500 KiB holds fewer than two 256 KiB images and throttles a 1 kHz writer; 8 MB removed
  // the stalls), and the receive socket absorbs as much.
  const std::uint64_t window = std::max<std::uint64_t>(d.transport.window_bytes(), 1u << 20);
  x << "<Internal><Watermarks><WhcHigh>" << window << "B</WhcHigh></Watermarks>"
    << "<SocketReceiveBufferSize min=\"default\" max=\"" << window << "B\"/>"
    << "<SocketSendBufferSize min=\"default\" max=\"" << std::min<std::uint64_t>(window, 4u << 20)
    << "B\"/></Internal>";
  if (d.transport.receive_buffer_bytes > 0) {
    x << "<Sizing><ReceiveBufferSize>" << d.transport.receive_buffer_bytes
      << "B</ReceiveBufferSize></Sizing>";
  }

  if (d.shared_memory.enabled) {
    x << "<SharedMemory><Enable>true</Enable><LogLevel>warn</LogLevel></SharedMemory>";
  }

  if (d.security.enabled) {
    const IdentityFiles f = identity_files(d.security.dir, participant);
    // Debian installs the plugins outside the search path; libddsc finds them itself there.
    x << "<Security><Authentication>"
      << "<IdentityCA>" << file_uri(f.ca_cert) << "</IdentityCA>"
      << "<IdentityCertificate>" << file_uri(f.cert) << "</IdentityCertificate>"
      << "<PrivateKey>" << file_uri(f.key) << "</PrivateKey>"
      << "</Authentication><AccessControl>"
      << "<PermissionsCA>" << file_uri(f.ca_cert) << "</PermissionsCA>"
      << "<Governance>" << file_uri(f.governance) << "</Governance>"
      << "<Permissions>" << file_uri(f.permissions) << "</Permissions>"
      << "</AccessControl><Cryptographic/></Security>";
  }
  x << "</Domain></CycloneDDS>";
  return x.str();
}

}  // namespace avs::deploy
