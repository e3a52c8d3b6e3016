#include "avs/bag/qos_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <sstream>

#include "avs/runtime/error.hpp"

namespace avs::bag {

namespace {

using runtime::Duration;
using runtime::dds::EndpointQos;

constexpr std::int64_t kInfiniteSec = 2147483647;
constexpr std::int64_t kInfiniteNsec = 4294967295;

void put_duration(std::ostringstream& out, const char* name, const std::optional<Duration>& d) {
  std::int64_t sec = kInfiniteSec;
  std::int64_t nsec = kInfiniteNsec;
  if (d) {
    sec = d->count() / 1'000'000'000;
    nsec = d->count() % 1'000'000'000;
  }
  out << "  " << name << ":\n    sec: " << sec << "\n    nsec: " << nsec << "\n";
}

std::optional<Duration> get_duration(const YAML::Node& node) {
  if (!node || !node.IsMap()) return std::nullopt;
  const auto sec = node["sec"].as<std::int64_t>(kInfiniteSec);
  const auto nsec = node["nsec"].as<std::int64_t>(kInfiniteNsec);
  if (sec >= kInfiniteSec && nsec >= kInfiniteNsec) return std::nullopt;
  if (sec >= kInfiniteSec) return std::nullopt;  // Jazzy writes infinity with other nsec values
  return Duration(sec * 1'000'000'000 + nsec);
}

}  // namespace

std::string offered_qos_yaml(const std::vector<EndpointQos>& profiles) {
  std::ostringstream out;
  for (const auto& q : profiles) {
    out << "- history: " << (q.keep_all ? 2 : 1) << "\n";
    out << "  depth: " << (q.keep_all ? 0 : q.depth) << "\n";
    out << "  reliability: " << (q.reliable ? 1 : 2) << "\n";
    out << "  durability: " << (q.transient_local ? 1 : 2) << "\n";
    put_duration(out, "deadline", q.deadline);
    put_duration(out, "lifespan", q.lifespan);
    out << "  liveliness: " << (q.liveliness_automatic ? 1 : 3) << "\n";
    put_duration(out, "liveliness_lease_duration", q.liveliness_lease);
    out << "  avoid_ros_namespace_conventions: false\n";
  }
  return out.str();
}

std::vector<EndpointQos> parse_offered_qos_yaml(std::string_view yaml) {
  std::vector<EndpointQos> result;
  if (yaml.find_first_not_of(" \t\r\n") == std::string_view::npos) return result;
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    throw runtime::Error("offered_qos_profiles: not YAML: " + std::string(e.what()));
  }
  if (!root.IsSequence()) {
    throw runtime::Error("offered_qos_profiles: expected a YAML list of QoS profiles");
  }
  for (const auto& node : root) {
    if (!node.IsMap()) throw runtime::Error("offered_qos_profiles: a list entry is not a map");
    EndpointQos q;
    try {
      q.keep_all = node["history"].as<int>(1) == 2;
      q.depth = node["depth"].as<std::int32_t>(10);
      q.reliable = node["reliability"].as<int>(1) != 2;
      q.transient_local = node["durability"].as<int>(2) == 1;
      q.deadline = get_duration(node["deadline"]);
      q.lifespan = get_duration(node["lifespan"]);
      q.liveliness_automatic = node["liveliness"].as<int>(1) != 3;
      q.liveliness_lease = get_duration(node["liveliness_lease_duration"]);
    } catch (const YAML::Exception& e) {
      throw runtime::Error("offered_qos_profiles: bad value: " + std::string(e.what()));
    }
    if (!q.keep_all && q.depth <= 0) q.depth = 10;  // rmw "system default" depth 0
    result.push_back(q);
  }
  return result;
}

EndpointQos replay_qos(const std::vector<EndpointQos>& profiles) {
  if (profiles.empty()) return EndpointQos{};
  return profiles.front();
}

}  // namespace avs::bag
