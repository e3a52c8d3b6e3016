// avs graph: the live graph seen through DDS discovery and /diagnostics: participants (named
// by the containers' diagnostics), components with their health, topics with publishers,
// subscribers and measured rates, and every publisher/subscriber pair whose QoS keeps DDS
// from matching them, named plainly.
#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <thread>

#include "avs/msg/type_registry.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/error.hpp"
#include "avs/runtime/raw_topic.hpp"
#include "avs/runtime/topic_name.hpp"
#include "commands.hpp"
#include "dds_environment.hpp"
#include "diagnostic_msgs.h"

namespace avs::cli {
namespace {

using Clock = std::chrono::steady_clock;

/// Hex of a GUID: the 12-byte prefix names a participant, all 16 bytes an endpoint.
std::string guid_text(const std::uint8_t* g, int bytes = 12) {
  std::ostringstream s;
  for (int i = 0; i < bytes; ++i) s << std::hex << std::setw(2) << std::setfill('0') << int(g[i]);
  return s.str();
}

/// The QoS policies that decide matching, read from a discovered endpoint.
struct MatchQos {
  bool reliable = false;
  bool transient_local = false;
  dds_duration_t deadline = DDS_INFINITY;
  dds_liveliness_kind_t liveliness = DDS_LIVELINESS_AUTOMATIC;
  dds_duration_t liveliness_lease = DDS_INFINITY;
  bool exclusive = false;
  std::vector<std::string> partitions;
  std::vector<dds_data_representation_id_t> representations;
  std::string text;
};

MatchQos read_qos(const dds_qos_t* q) {
  MatchQos e;
  dds_reliability_kind_t rel;
  dds_duration_t blocking;
  if (q != nullptr && dds_qget_reliability(q, &rel, &blocking))
    e.reliable = rel == DDS_RELIABILITY_RELIABLE;
  dds_durability_kind_t dur;
  if (q != nullptr && dds_qget_durability(q, &dur))
    e.transient_local = dur != DDS_DURABILITY_VOLATILE;
  if (q != nullptr) dds_qget_deadline(q, &e.deadline);
  if (q != nullptr) dds_qget_liveliness(q, &e.liveliness, &e.liveliness_lease);
  dds_ownership_kind_t own;
  if (q != nullptr && dds_qget_ownership(q, &own)) e.exclusive = own == DDS_OWNERSHIP_EXCLUSIVE;
  uint32_t n = 0;
  char** ps = nullptr;
  if (q != nullptr && dds_qget_partition(q, &n, &ps)) {
    for (uint32_t i = 0; i < n; ++i) {
      e.partitions.emplace_back(ps[i]);
      dds_free(ps[i]);
    }
    dds_free(ps);
  }
  uint32_t nr = 0;
  dds_data_representation_id_t* reps = nullptr;
  if (q != nullptr && dds_qget_data_representation(q, &nr, &reps)) {
    e.representations.assign(reps, reps + nr);
    dds_free(reps);
  }
  if (e.representations.empty()) e.representations.push_back(DDS_DATA_REPRESENTATION_XCDR1);
  e.text = e.reliable ? "reliable" : "best_effort";
  e.text += e.transient_local ? ", transient_local" : ", volatile";
  if (e.deadline != DDS_INFINITY)
    e.text += ", deadline " + std::to_string(e.deadline / 1000000) + " ms";
  if (!e.partitions.empty()) {
    e.text += ", partition";
    for (const auto& p : e.partitions) e.text += " '" + p + "'";
  }
  return e;
}

struct Endpoint {
  std::string participant;  ///< GUID prefix text
  std::string topic, type;
  MatchQos qos;
};

std::string partitions_text(const std::vector<std::string>& p) {
  if (p.empty()) return "the default partition";
  std::string s;
  for (const auto& x : p) s += (s.empty() ? "'" : ", '") + x + "'";
  return "partition " + s;
}

bool partitions_meet(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  if (a.empty() && b.empty()) return true;
  const std::vector<std::string> def = {""};
  const auto& x = a.empty() ? def : a;
  const auto& y = b.empty() ? def : b;
  for (const auto& i : x) {
    for (const auto& j : y) {
      if (i == j) return true;
    }
  }
  return false;
}

/// Why a publisher and a subscriber of one topic cannot match ("" when they can).
std::vector<std::string> mismatch(const Endpoint& pub, const Endpoint& sub) {
  std::vector<std::string> why;
  if (pub.type != sub.type) {
    why.push_back("types differ: " + runtime::to_ros_type_name(pub.type) + " vs " +
                  runtime::to_ros_type_name(sub.type));
  }
  if (sub.qos.reliable && !pub.qos.reliable) {
    why.push_back("the subscriber requires RELIABLE, the publisher offers BEST_EFFORT");
  }
  if (sub.qos.transient_local && !pub.qos.transient_local) {
    why.push_back("the subscriber requires TRANSIENT_LOCAL durability, the publisher is VOLATILE");
  }
  if (sub.qos.deadline < pub.qos.deadline) {
    why.push_back("the subscriber's deadline (" + std::to_string(sub.qos.deadline / 1000000) +
                  " ms) is shorter than the publisher's");
  }
  if (sub.qos.liveliness > pub.qos.liveliness ||
      sub.qos.liveliness_lease < pub.qos.liveliness_lease) {
    why.push_back("the subscriber's liveliness is stricter than the publisher's");
  }
  if (sub.qos.exclusive != pub.qos.exclusive) why.push_back("ownership kinds differ");
  if (!partitions_meet(pub.qos.partitions, sub.qos.partitions)) {
    why.push_back("the publisher is in " + partitions_text(pub.qos.partitions) +
                  ", the subscriber in " + partitions_text(sub.qos.partitions));
  }
  const auto& w = pub.qos.representations.front();  // a writer uses its first one
  if (std::find(sub.qos.representations.begin(), sub.qos.representations.end(), w) ==
      sub.qos.representations.end()) {
    why.push_back(std::string("the publisher writes ") +
                  (w == DDS_DATA_REPRESENTATION_XCDR2 ? "XCDR2" : "XCDR1") +
                  ", which the subscriber does not accept");
  }
  return why;
}

struct Options {
  int domain = 0;  // add_domain_option
  double duration_s = 3.0;
  bool no_rates = false;  // --no-rates
  bool verbose = false;   // -v: DDS names too
};

int run_graph_view(const Options& o) {
  const int domain = o.domain;
  runtime::dds::Participant participant(static_cast<dds_domainid_t>(domain),
                                        environment_partition());
  runtime::dds::EndpointDiscovery discovery(participant);

  // /diagnostics names the participants (container/component) and carries their health.
  const msg::TypeEntry* diag_type = msg::find_type("diagnostic_msgs::msg::dds_::DiagnosticArray_");
  runtime::QosProfile diag_profile;
  runtime::dds::Topic diag_topic(participant, diag_type->descriptor, "rt/diagnostics",
                                 diag_profile);
  runtime::Qos diag_qos(diag_profile);
  participant.apply_partition(diag_qos.get());
  runtime::dds::Entity diag_reader(runtime::check_dds(
      dds_create_reader(participant.get(), diag_topic.get(), diag_qos.get(), nullptr),
      "reader on rt/diagnostics"));

  std::map<std::string, Endpoint> endpoints;            // endpoint GUID -> endpoint
  std::map<std::string, std::string> participant_name;  // participant GUID -> container
  struct Health {
    int level = 0;
    std::string message, type;
    std::map<std::string, std::string> values;
  };
  std::map<std::string, Health> health;  // "container/component" -> last status

  struct Counter {
    std::unique_ptr<runtime::dds::Topic> topic;
    runtime::dds::Entity reader;
    std::uint64_t samples = 0;
  };
  std::map<std::string, Counter> counters;
  std::uint64_t diag_samples = 0;  // /diagnostics is read above, not by a counter
  Clock::time_point rate_start{};

  // The endpoints DDS discovery shows now (those gone dropped), keyed by GUID text + w/r.
  auto take_endpoints = [&] {
    discovery.update();
    endpoints.clear();
    for (const auto& [key, ep] : discovery.endpoints()) {
      endpoints[guid_text(ep.key.data(), 16) + (ep.is_writer ? "w" : "r")] = Endpoint{
          guid_text(ep.participant.data()), ep.topic, ep.type_name, read_qos(ep.qos.get())};
    }
  };
  auto take_diagnostics = [&] {
    void* samples[16] = {};
    dds_sample_info_t infos[16];
    int n;
    while ((n = dds_take(diag_reader.get(), samples, infos, 16, 16)) > 0) {
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        if (rate_start != Clock::time_point{}) ++diag_samples;
        const auto* a = static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[i]);
        dds_builtintopic_endpoint_t* w =
            dds_get_matched_publication_data(diag_reader.get(), infos[i].publication_handle);
        std::string container;
        for (uint32_t k = 0; k < a->status._length; ++k) {
          const auto& s = a->status._buffer[k];
          const std::string name = s.name != nullptr ? s.name : "";
          container = name.substr(0, name.find('/'));
          Health h{s.level, s.message ? s.message : "", s.hardware_id ? s.hardware_id : "", {}};
          for (uint32_t v = 0; v < s.values._length; ++v) {
            h.values[s.values._buffer[v].key] = s.values._buffer[v].value;
          }
          health[name] = std::move(h);
        }
        if (w != nullptr) {
          if (!container.empty()) participant_name[guid_text(w->participant_key.v)] = container;
          dds_builtintopic_free_endpoint(w);
        }
      }
      dds_return_loan(diag_reader.get(), samples, n);
    }
  };

  // Discovery and diagnostics (1 Hz) first, then count samples per topic.
  const auto start = Clock::now();
  const auto discover_until =
      start + std::chrono::milliseconds(static_cast<int>(1000 * std::max(1.2, o.duration_s / 2)));
  const auto end = start + std::chrono::milliseconds(static_cast<int>(1000 * o.duration_s));
  while (Clock::now() < end) {
    take_endpoints();
    take_diagnostics();
    if (!o.no_rates && rate_start == Clock::time_point{} && Clock::now() >= discover_until) {
      for (const auto& [key, e] : endpoints) {
        if (key.back() != 'w' || counters.count(e.topic)) continue;
        const msg::TypeEntry* t = msg::find_type(e.type);
        if (t == nullptr) continue;
        runtime::QosProfile p;  // best effort matches every writer
        p.reliability = runtime::Reliability::best_effort;
        p.depth = 64;
        Counter c;
        try {
          c.topic = std::make_unique<runtime::dds::Topic>(participant, t->descriptor, e.topic, p);
          runtime::Qos q(p);
          participant.apply_partition(q.get());
          c.reader = runtime::dds::Entity(runtime::check_dds(
              dds_create_reader(participant.get(), c.topic->get(), q.get(), nullptr), "reader"));
        } catch (const std::exception&) {
          continue;
        }
        counters.emplace(e.topic, std::move(c));
      }
      rate_start = Clock::now();
    }
    for (auto& [topic, c] : counters) {
      void* samples[64] = {};
      dds_sample_info_t infos[64];
      int n;
      while ((n = dds_take(c.reader.get(), samples, infos, 64, 64)) > 0) {
        for (int i = 0; i < n; ++i) c.samples += infos[i].valid_data ? 1 : 0;
        dds_return_loan(c.reader.get(), samples, n);
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const double rate_window = rate_start == Clock::time_point{}
                                 ? 0
                                 : std::chrono::duration<double>(Clock::now() - rate_start).count();

  auto who = [&](const std::string& guid) {
    auto it = participant_name.find(guid);
    return it != participant_name.end() ? "'" + it->second + "'"
                                        : "participant " + guid.substr(0, 8) + "…";
  };

  std::cout << "avs graph: domain " << domain << ", " << std::fixed << std::setprecision(1)
            << o.duration_s << " s of discovery\n";
  std::cout << "components (from /diagnostics):\n";
  if (health.empty())
    std::cout << "  (none reported; containers publish /diagnostics every second)\n";
  for (const auto& [name, h] : health) {
    static const char* levels[] = {"OK", "WARN", "ERROR", "STALE"};
    std::cout << "  " << std::left << std::setw(32) << name << std::setw(20) << h.type
              << (h.level >= 0 && h.level < 4 ? levels[h.level] : "?") << "  " << h.message;
    for (const auto& [k, v] : h.values) std::cout << "  " << k << "=" << v;
    std::cout << "\n";
  }
  std::map<std::string, std::vector<const Endpoint*>> by_topic_pub, by_topic_sub;
  std::set<std::string> topics;
  for (const auto& [key, e] : endpoints) {
    if (e.topic.rfind("DCPS", 0) == 0) continue;
    // Services (the parameter services' rq/..Request, rr/..Reply) are not topics; `avs node
    // info` lists them.
    if (e.topic.rfind("rq/", 0) == 0 || e.topic.rfind("rr/", 0) == 0) continue;
    // Nor is the DDS-only ros_discovery_info (as in `avs topic list`); -v shows it.
    if (!o.verbose && e.topic == "ros_discovery_info") continue;
    topics.insert(e.topic);
    (key.back() == 'w' ? by_topic_pub : by_topic_sub)[e.topic].push_back(&e);
  }
  std::cout << "topics:\n";
  for (const auto& t : topics) {
    const auto& ps = by_topic_pub[t];
    const auto& ss = by_topic_sub[t];
    const std::string ros = t.rfind("rt/", 0) == 0 ? t.substr(2) : t;
    std::cout << "  " << std::left << std::setw(28) << ros;
    auto c = counters.find(t);
    const bool counted = c != counters.end() || t == "rt/diagnostics";
    if (counted && rate_window > 0) {
      const auto n = c != counters.end() ? c->second.samples : diag_samples;
      std::cout << std::right << std::setw(9) << std::setprecision(1)
                << static_cast<double>(n) / rate_window << " Hz  ";
    } else {
      std::cout << std::right << std::setw(9) << "-"
                << "     ";
    }
    const Endpoint* any = !ps.empty() ? ps.front() : ss.front();
    // ROS names where a person reads (issue 18 section 4); the DDS ones with -v.
    std::cout << runtime::to_ros_type_name(any->type);
    if (o.verbose) std::cout << "  (DDS " << t << ", " << any->type << ")";
    std::cout << "\n";
    for (const auto* p : ps)
      std::cout << "      pub " << who(p->participant) << " [" << p->qos.text << "]\n";
    for (const auto* s : ss)
      std::cout << "      sub " << who(s->participant) << " [" << s->qos.text << "]\n";
  }
  int problems = 0;
  std::cout << "QoS mismatches:\n";
  for (const auto& t : topics) {
    const std::string ros = t.rfind("rt/", 0) == 0 ? t.substr(2) : t;
    for (const auto* s : by_topic_sub[t]) {
      for (const auto* p : by_topic_pub[t]) {
        // One participant is one container: its components get each other's samples in
        // process, whatever the QoS, and its DDS readers ignore its own writers.
        if (p->participant == s->participant) continue;
        for (const auto& why : mismatch(*p, *s)) {
          ++problems;
          std::cout << "  " << ros << ": publisher " << who(p->participant) << " and subscriber "
                    << who(s->participant) << " will never match: " << why << "\n";
        }
      }
    }
  }
  if (problems == 0) std::cout << "  none\n";
  return problems == 0 ? 0 : 3;
}

void add_graph_command(Command& app) {
  auto* cmd = app.add_subcommand(
      "graph",
      "Live graph: components and health, topics with rates, QoS mismatches named plainly");
  static Options o;
  add_domain_option(cmd, o.domain);
  cmd->add_option("--duration", o.duration_s,
                  "seconds to observe (rates are measured in the second half)")
      ->capture_default_str()
      ->check_range(0.1, 3600);
  cmd->add_flag("--no-rates", o.no_rates, "do not subscribe to topics to measure rates");
  cmd->add_flag("-v,--verbose", o.verbose, "DDS topic and type names too");
  cmd->footer(
      "Exit status 3 when a publisher and a subscriber of one topic cannot match.\n"
      "On a deployment: eval \"$(avs deploy env DEPLOY.yaml --host H)\"; avs graph");
  cmd->callback([] {
    try {
      exit_status() = run_graph_view(o);
    } catch (const std::exception& e) {
      std::cerr << "avs graph: " << e.what() << "\n";
      exit_status() = 1;
    }
  });
}

}  // namespace

AVS_REGISTER_COMMAND(add_graph_command)

}  // namespace avs::cli
