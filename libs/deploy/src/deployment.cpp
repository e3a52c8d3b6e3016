// load_deployment(): reads a deployment YAML (hosts, placement of a graph's containers, DDS
// settings) with the graph loader's reader, so errors look the same: file:line:column.
#include "avs/deploy/deployment.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "avs/graph/yaml_reader.hpp"

namespace avs::deploy {
namespace {

namespace fs = std::filesystem;
using graph::SourceLocation;
using graph::detail::Entry;
using graph::detail::FileReader;
using graph::detail::find_entry;
using graph::detail::map_entries;

const std::vector<std::string> top_keys = {"graph",     "args",          "domain_id",
                                           "partition", "discovery",     "transport",
                                           "security",  "shared_memory", "hosts"};
const std::vector<std::string> host_keys = {"name", "address", "interface", "containers"};
const std::vector<std::string> discovery_keys = {"multicast", "lease_duration_s",
                                                 "max_participants_per_host"};
const std::vector<std::string> transport_keys = {"image_bytes",   "image_rate_hz",
                                                 "buffer_ms",     "max_message_size",
                                                 "fragment_size", "receive_buffer_bytes"};
const std::vector<std::string> security_keys = {"enabled", "dir"};

bool is_host_name(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

bool is_ipv4(const std::string& s) {
  in_addr a{};
  return inet_pton(AF_INET, s.c_str(), &a) == 1;
}

/// Partition names: printable, no DDS wildcard characters (they would match other systems).
bool is_partition(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == '/';
  });
}

std::optional<bool> boolean(const FileReader& r, const YAML::Node& n, const std::string& what) {
  auto i = r.choice(n, what, {"false", "true"});
  if (!i) return std::nullopt;
  return *i == 1;
}

std::optional<YAML::Node> parse(graph::detail::Diagnostics& diags, const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    diags.error({path, 1, 1}, "cannot open deployment file '" + path + "'");
    return std::nullopt;
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    return YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    const SourceLocation where = e.mark.is_null()
                                     ? SourceLocation{path, 1, 1}
                                     : SourceLocation{path, e.mark.line + 1, e.mark.column + 1};
    diags.error(where, "YAML syntax error: " + e.msg);
    return std::nullopt;
  }
}

struct Reading {
  Deployment d;
  FileReader reader;
  std::optional<SourceLocation> graph_where;
  std::map<std::string, SourceLocation> placed;  ///< container -> where it was placed
  bool domain_given = false;
  bool check_security_files = true;
};

void read_hosts(Reading& st, const YAML::Node& node) {
  const FileReader& r = st.reader;
  if (!node.IsSequence() || node.size() == 0) {
    r.error(node, "'hosts': expected a non-empty list of {name, address, interface, containers}");
    return;
  }
  std::map<std::string, SourceLocation> names, addresses;
  for (const auto& item : node) {
    auto fields = map_entries(r, item, "host", host_keys);
    if (!item.IsMap()) continue;
    Host h;
    h.where = r.at(item);
    const Entry* name = find_entry(fields, "name");
    if (name == nullptr) {
      r.error(item, "host: missing required key 'name'");
      continue;
    }
    if (auto v = r.string(name->value, "host 'name'")) {
      h.name = *v;
      if (!is_host_name(h.name)) {
        r.error(name->value, "host 'name': '" + h.name +
                                 "' is not a host name (letters, digits, '_' and '-', not "
                                 "starting with a digit)");
      } else if (auto [it, fresh] = names.emplace(h.name, r.at(name->value)); !fresh) {
        r.error(name->value,
                "host 'name': '" + h.name + "' is already used at " + it->second.str());
      }
    }
    const std::string what = "host '" + h.name + "'";
    if (const Entry* e = find_entry(fields, "address")) {
      if (auto v = r.string(e->value, what + " 'address'")) {
        if (!is_ipv4(*v)) {
          r.error(e->value, what + " 'address': '" + *v + "' is not an IPv4 address like 10.0.0.2");
        } else if (auto [it, fresh] = addresses.emplace(*v, r.at(e->value)); !fresh) {
          r.error(e->value, what + " 'address': " + *v + " is already used at " + it->second.str());
        } else {
          h.address = *v;
        }
      }
    }
    if (const Entry* e = find_entry(fields, "interface")) {
      if (auto v = r.string(e->value, what + " 'interface'")) {
        if (v->empty() || v->size() > 15 || v->find_first_of(" /") != std::string::npos) {
          r.error(e->value, what + " 'interface': '" + *v + "' is not a network interface name");
        } else {
          h.interface = *v;
        }
      }
    }
    const Entry* containers = find_entry(fields, "containers");
    if (containers == nullptr) {
      r.error(item, what + ": missing required key 'containers' (graph containers it runs)");
    } else if (!containers->value.IsSequence()) {
      r.error(containers->value, what + " 'containers': expected a list of container names, got " +
                                     graph::detail::node_kind(containers->value));
    } else {
      for (const auto& c : containers->value) {
        auto v = r.string(c, what + " container");
        if (!v) continue;
        if (auto [it, fresh] = st.placed.emplace(*v, r.at(c)); !fresh) {
          r.error(c, "container '" + *v + "' is placed twice; first at " + it->second.str());
          continue;
        }
        h.containers.push_back(*v);
      }
    }
    st.d.hosts.push_back(std::move(h));
  }
}

void read_discovery(Reading& st, const YAML::Node& node) {
  const FileReader& r = st.reader;
  for (const auto& e : map_entries(r, node, "'discovery'", discovery_keys)) {
    const std::string what = "discovery '" + e.key + "'";
    if (e.key == "multicast") {
      if (auto v = boolean(r, e.value, what)) st.d.discovery.multicast = *v;
    } else if (e.key == "lease_duration_s") {
      if (auto v = r.number(e.value, what, 0.1, 3600.0)) st.d.discovery.lease_duration_s = *v;
    } else if (e.key == "max_participants_per_host") {
      if (auto v = r.integer(e.value, what, 1, 120)) {
        st.d.discovery.max_participants_per_host = static_cast<int>(*v);
      }
    }
  }
}

void read_transport(Reading& st, const YAML::Node& node) {
  const FileReader& r = st.reader;
  auto& t = st.d.transport;
  for (const auto& e : map_entries(r, node, "'transport'", transport_keys)) {
    const std::string what = "transport '" + e.key + "'";
    if (e.key == "image_bytes") {
      if (auto v = r.integer(e.value, what, 1, std::int64_t{1} << 32)) t.image_bytes = *v;
    } else if (e.key == "image_rate_hz") {
      if (auto v = r.number(e.value, what, 0.001, 1e6)) t.image_rate_hz = *v;
    } else if (e.key == "buffer_ms") {
      if (auto v = r.number(e.value, what, 1.0, 10000.0)) t.buffer_ms = *v;
    } else if (e.key == "max_message_size") {
      // Cyclone accepts up to 65500 B of UDP payload; below ~1 KiB nothing useful fits.
      if (auto v = r.integer(e.value, what, 1024, 65500)) t.max_message_size = *v;
    } else if (e.key == "fragment_size") {
      if (auto v = r.integer(e.value, what, 0, 65500)) t.fragment_size = *v;
    } else if (e.key == "receive_buffer_bytes") {
      if (auto v = r.integer(e.value, what, 0, std::int64_t{1} << 30)) {
        if (*v != 0 && static_cast<std::uint64_t>(*v) < Transport::kMinReceiveBufferBytes) {
          r.error(e.value, what + ": " + std::to_string(*v) + " is below " +
                               std::to_string(Transport::kMinReceiveBufferBytes) +
                               " (or 0: Cyclone's default)");
        } else {
          t.receive_buffer_bytes = *v;
        }
      }
    }
  }
  if (t.fragment_size > t.max_message_size) {
    r.error(node, "'transport': fragment_size (" + std::to_string(t.fragment_size) +
                      ") must not exceed max_message_size (" + std::to_string(t.max_message_size) +
                      ")");
  }
}

void read_security(Reading& st, const Entry& entry) {
  const FileReader& r = st.reader;
  std::optional<YAML::Node> dir_node;
  std::string dir_text;
  for (const auto& e : map_entries(r, entry.value, "'security'", security_keys)) {
    if (e.key == "enabled") {
      if (auto v = boolean(r, e.value, "security 'enabled'")) st.d.security.enabled = *v;
    } else if (e.key == "dir") {
      auto v = r.string(e.value, "security 'dir'");
      if (!v) continue;
      fs::path p(*v);
      if (p.is_relative()) p = fs::path(st.d.file).parent_path() / p;
      st.d.security.dir = fs::absolute(p).lexically_normal().string();
      dir_node = e.value;
      dir_text = *v;
    }
  }
  if (!st.d.security.enabled) return;
  if (!dir_node) {
    r.error(entry.key_node, "'security': enabled needs 'dir' (the folder of avs security init)");
  } else if (st.check_security_files &&
             !fs::is_regular_file(fs::path(st.d.security.dir) / "ca_cert.pem")) {
    r.error(*dir_node, "security 'dir': no CA in '" + st.d.security.dir +
                           "' (run: avs security init " + dir_text + " --deployment " + st.d.file +
                           ")");
  }
}

}  // namespace

std::uint64_t Transport::window_bytes() const {
  return static_cast<std::uint64_t>(
      std::ceil(static_cast<double>(image_bytes) * image_rate_hz * buffer_ms / 1000.0));
}

const Host* Deployment::find_host(const std::string& name) const {
  for (const auto& h : hosts) {
    if (h.name == name) return &h;
  }
  return nullptr;
}

const Host* Deployment::host_of(const std::string& container) const {
  for (const auto& h : hosts) {
    if (std::find(h.containers.begin(), h.containers.end(), container) != h.containers.end()) {
      return &h;
    }
  }
  return nullptr;
}

std::vector<std::string> Deployment::host_names() const {
  std::vector<std::string> out;
  for (const auto& h : hosts) out.push_back(h.name);
  return out;
}

bool is_deployment_file(const std::string& file) {
  try {
    const YAML::Node root = YAML::LoadFile(file);
    return root.IsMap() && root["hosts"].IsDefined();
  } catch (const YAML::Exception&) {
    return false;  // the graph loader reports the syntax error
  }
}

LoadResult load_deployment(const std::string& file,
                           const std::map<std::string, std::string>& overrides,
                           bool check_security_files) {
  graph::detail::Diagnostics diags;
  Reading st;
  st.check_security_files = check_security_files;
  st.d.file = file;
  st.reader.file = file;
  st.reader.diags = &diags;
  LoadResult result;
  auto root = parse(diags, file);
  if (root && !root->IsMap()) {
    st.reader.error(*root, "deployment file: expected a mapping with 'graph' and 'hosts', got " +
                               graph::detail::node_kind(*root));
    root.reset();
  }
  if (root) {
    const auto entries = map_entries(st.reader, *root, "deployment file", top_keys);
    const FileReader& r = st.reader;
    if (const Entry* e = find_entry(entries, "graph")) {
      if (auto v = r.string(e->value, "'graph'")) {
        fs::path p(*v);
        if (p.is_relative()) p = fs::path(file).parent_path() / p;
        st.d.graph_file = p.lexically_normal().string();
        st.graph_where = r.at(e->value);
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) {
          r.error(e->value,
                  "'graph': file '" + *v + "' not found (looked for '" + st.d.graph_file + "')");
          st.d.graph_file.clear();
        }
      }
    } else {
      r.error(*root, "deployment file: missing required key 'graph' (the graph YAML it places)");
    }
    if (const Entry* e = find_entry(entries, "args")) {
      for (const auto& a : map_entries(r, e->value, "'args'", {})) {
        if (auto v = r.string(a.value, "argument '" + a.key + "'")) st.d.graph_args[a.key] = *v;
      }
    }
    for (const auto& [k, v] : overrides) st.d.graph_args[k] = v;
    if (const Entry* e = find_entry(entries, "domain_id")) {
      if (auto v = r.integer(e->value, "'domain_id'", 0, 232)) {
        st.d.domain_id = static_cast<int>(*v);
        st.domain_given = true;
      }
    }
    if (const Entry* e = find_entry(entries, "partition")) {
      if (auto v = r.string(e->value, "'partition'")) {
        if (!is_partition(*v)) {
          r.error(e->value, "'partition': '" + *v +
                                "' must be letters, digits, '_', '-', '.' or '/' (no wildcards)");
        } else {
          st.d.partition = *v;
        }
      }
    }
    if (const Entry* e = find_entry(entries, "discovery")) read_discovery(st, e->value);
    if (const Entry* e = find_entry(entries, "transport")) read_transport(st, e->value);
    if (const Entry* e = find_entry(entries, "security")) read_security(st, *e);
    if (const Entry* e = find_entry(entries, "shared_memory")) {
      if (auto v = boolean(r, e->value, "'shared_memory'")) st.d.shared_memory.enabled = *v;
    }
    const Entry* hosts = find_entry(entries, "hosts");
    if (hosts == nullptr) {
      r.error(*root, "deployment file: missing required key 'hosts'");
    } else {
      read_hosts(st, hosts->value);
    }
    if (!st.d.discovery.multicast) {
      for (const auto& h : st.d.hosts) {
        if (h.address.empty() && st.d.hosts.size() > 1) {
          diags.error(h.where, "host '" + h.name +
                                   "': 'address' is required with discovery multicast: false "
                                   "(the other hosts send discovery to it)");
        }
      }
    }
  }

  // The graph, with the deployment's arguments; its errors come after the deployment's.
  std::vector<graph::Diagnostic> graph_errors;
  if (!st.d.graph_file.empty()) {
    graph::LoadResult g = graph::load_graph(st.d.graph_file, st.d.graph_args);
    graph_errors = std::move(g.errors);
    if (g.graph) {
      st.d.graph = std::move(*g.graph);
      std::vector<std::string> names;
      for (const auto& c : st.d.graph.containers) names.push_back(c.name);
      for (const auto& [name, where] : st.placed) {
        if (st.d.graph.find_container(name) == nullptr) {
          diags.error(where, "container '" + name + "' is not in graph '" + st.d.graph_file + "'" +
                                 graph::detail::did_you_mean(name, names) +
                                 "; containers: " + graph::detail::join_quoted(names));
        }
      }
      for (const auto& c : st.d.graph.containers) {
        auto it = st.placed.find(c.name);
        if (it == st.placed.end()) {
          diags.error(st.graph_where.value_or(SourceLocation{file, 1, 1}),
                      "graph container '" + c.name + "' (" + c.where.str() +
                          ") is placed on no host; add it to one host's 'containers'");
        } else if (!c.host.empty()) {
          const Host* h = st.d.host_of(c.name);
          if (h != nullptr && h->name != c.host) {
            diags.error(it->second, "container '" + c.name + "' is placed on host '" + h->name +
                                        "' but the graph says host '" + c.host + "' (" +
                                        c.where.str() + ")");
          }
        }
      }
      if (!st.domain_given) st.d.domain_id = st.d.graph.domain_id;
    }
  }
  result.errors = diags.take();
  std::stable_sort(result.errors.begin(), result.errors.end(),
                   [](const graph::Diagnostic& a, const graph::Diagnostic& b) {
                     if (a.where.line != b.where.line) return a.where.line < b.where.line;
                     return a.where.column < b.where.column;
                   });
  result.errors.insert(result.errors.end(), graph_errors.begin(), graph_errors.end());
  if (result.errors.empty()) result.deployment = std::move(st.d);
  return result;
}

}  // namespace avs::deploy
