// ParameterClient: one request, its reply matched by (client id, sequence number).
#include "parameter_client.hpp"

#include <algorithm>
#include <set>
#include <thread>

#include "avs/runtime/sample.hpp"
#include "interrupts.hpp"

namespace avs::cli {

namespace rcl = msgs::rcl_interfaces;
using Clock = std::chrono::steady_clock;

namespace {

/// " on domain 7" or " on domain 7, partition 'rig'".
std::string where(const runtime::dds::Participant& participant) {
  dds_domainid_t domain = 0;
  runtime::check_dds(dds_get_domainid(participant.get(), &domain), "domain id");
  return " on domain " + std::to_string(domain) +
         (participant.partition().empty() ? "" : ", partition '" + participant.partition() + "'");
}

/// Does the endpoint with `qos` talk to endpoints of `partition` ("" = the default partition)?
bool in_partition(const dds_qos_t* qos, const std::string& partition) {
  std::uint32_t n = 0;
  char** names = nullptr;
  bool found = false;
  if (qos != nullptr && dds_qget_partition(qos, &n, &names)) {
    for (std::uint32_t i = 0; i < n; ++i) {
      found = found || partition == names[i];
      dds_free(names[i]);
    }
    dds_free(names);
  }
  return n == 0 ? partition.empty() : found;
}

}  // namespace

ParameterClient::ParameterClient(const runtime::dds::Participant& participant, std::string node,
                                 std::chrono::milliseconds timeout)
    : participant_(participant), node_(std::move(node)), timeout_(timeout) {}

template <class Request, class Response, class Fill>
std::shared_ptr<Response> ParameterClient::call(const char* service, Fill fill) {
  const runtime::QosProfile qos = runtime::service_qos();
  runtime::dds::Topic request_topic(participant_, msg::TypeSupport<Request>::descriptor(),
                                    runtime::parameter_request_topic(node_, service), qos);
  runtime::dds::Topic reply_topic(participant_, msg::TypeSupport<Response>::descriptor(),
                                  runtime::parameter_reply_topic(node_, service), qos);
  runtime::dds::Reader reader(participant_, reply_topic, qos);
  runtime::dds::Writer writer(participant_, request_topic, qos);

  // 1. The node's service must be there: its request reader and its reply writer.
  const auto deadline = Clock::now() + timeout_;
  for (;;) {
    dds_subscription_matched_status_t replies{};
    runtime::check_dds(dds_get_subscription_matched_status(reader.get(), &replies),
                       "matched status of " + reply_topic.name());
    if (writer.matched_readers() > 0 && replies.current_count > 0) break;
    if (stop_requested()) throw runtime::Error("interrupted");
    if (Clock::now() > deadline) {
      throw runtime::Error("no node " + node_ + " answers " + service + where(participant_) +
                           " (`avs param list` shows the nodes that do)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }

  // 2. The request, with rmw_cyclonedds's header: our writer's instance handle and a sequence.
  auto request = runtime::make_sample<Request>();
  dds_instance_handle_t client = 0;
  runtime::check_dds(dds_get_instance_handle(writer.get(), &client), "instance handle");
  request->client_guid = client;
  request->sequence_number = ++sequence_;
  fill(*request);
  writer.write(request.get());

  // 3. Its reply.
  for (;;) {
    auto reply = runtime::make_sample<Response>();
    void* buffers[1] = {reply.get()};
    dds_sample_info_t info;
    const dds_return_t n = dds_take(reader.get(), buffers, &info, 1, 1);
    if (n > 0) {
      if (info.valid_data && reply->client_guid == client &&
          reply->sequence_number == request->sequence_number) {
        return reply;
      }
      continue;
    }
    if (stop_requested()) throw runtime::Error("interrupted");
    if (Clock::now() > deadline) {
      throw runtime::Error(node_ + " did not answer " + service + " within " +
                           runtime::format_number(static_cast<double>(timeout_.count()) / 1000.0) +
                           " s");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::vector<std::string> ParameterClient::list() {
  auto reply = call<rcl::ListParameters_Request, rcl::ListParameters_Response>(
      "list_parameters", [](rcl::ListParameters_Request& r) { r.depth = 0; });
  std::vector<std::string> names;
  for (const char* name : runtime::as_span(reply->result.names)) {
    names.emplace_back(runtime::get_string(name));
  }
  std::sort(names.begin(), names.end());
  return names;
}

namespace {
template <class Request>
void fill_names(Request& request, const std::vector<std::string>& names) {
  runtime::resize_sequence(request.names, static_cast<std::uint32_t>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    request.names._buffer[i] = nullptr;
    runtime::set_string(request.names._buffer[i], names[i]);
  }
}
}  // namespace

std::vector<std::optional<runtime::ParamValue>> ParameterClient::get(
    const std::vector<std::string>& names) {
  auto reply = call<rcl::GetParameters_Request, rcl::GetParameters_Response>(
      "get_parameters", [&](rcl::GetParameters_Request& r) { fill_names(r, names); });
  std::vector<std::optional<runtime::ParamValue>> values;
  for (const auto& v : runtime::as_span(reply->values)) values.push_back(runtime::from_message(v));
  values.resize(names.size());
  return values;
}

std::vector<ParameterDescription> ParameterClient::describe(const std::vector<std::string>& names) {
  auto reply = call<rcl::DescribeParameters_Request, rcl::DescribeParameters_Response>(
      "describe_parameters", [&](rcl::DescribeParameters_Request& r) { fill_names(r, names); });
  std::vector<ParameterDescription> out;
  for (const auto& d : runtime::as_span(reply->descriptors)) {
    ParameterDescription p;
    p.name = runtime::get_string(d.name);
    p.type = static_cast<runtime::RosParameterType>(d.type);
    p.description = runtime::get_string(d.description);
    p.constraints = runtime::get_string(d.additional_constraints);
    p.read_only = d.read_only;
    if (d.integer_range._length > 0) {
      p.range = {static_cast<double>(d.integer_range._buffer[0].from_value),
                 static_cast<double>(d.integer_range._buffer[0].to_value)};
    } else if (d.floating_point_range._length > 0) {
      p.range = {d.floating_point_range._buffer[0].from_value,
                 d.floating_point_range._buffer[0].to_value};
    }
    out.push_back(std::move(p));
  }
  // A node that leaves unknown names out (rclcpp does) still gives one entry per name.
  for (std::size_t i = out.size(); i < names.size(); ++i) out.push_back({names[i]});
  return out;
}

std::vector<std::string> ParameterClient::set(
    const std::vector<std::pair<std::string, runtime::ParamValue>>& values) {
  auto reply = call<rcl::SetParameters_Request, rcl::SetParameters_Response>(
      "set_parameters", [&](rcl::SetParameters_Request& r) {
        runtime::resize_sequence(r.parameters, static_cast<std::uint32_t>(values.size()));
        for (std::size_t i = 0; i < values.size(); ++i) {
          runtime::set_string(r.parameters._buffer[i].name, values[i].first);
          runtime::to_message(values[i].second, r.parameters._buffer[i].value);
        }
      });
  std::vector<std::string> reasons;
  for (const auto& result : runtime::as_span(reply->results)) {
    reasons.push_back(result.successful ? std::string()
                                        : std::string(runtime::get_string(result.reason)));
    if (!result.successful && reasons.back().empty()) reasons.back() = "refused (no reason given)";
  }
  reasons.resize(values.size(), "no result in the reply");
  return reasons;
}

std::vector<std::string> discover_parameter_nodes(const runtime::dds::Participant& participant,
                                                  std::chrono::milliseconds wait,
                                                  const std::string& wanted) {
  runtime::dds::Entity subs(runtime::check_dds(
      dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
      "read DCPSSubscription"));
  dds_guid_t own{};
  runtime::check_dds(dds_get_guid(participant.get(), &own), "participant guid");
  std::set<std::string> nodes;
  const auto deadline = Clock::now() + wait;
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    void* samples[256] = {};
    dds_sample_info_t infos[256];
    const int n =
        runtime::check_dds(dds_read(subs.get(), samples, infos, 256, 256), "read discovery");
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data || infos[i].instance_state != DDS_IST_ALIVE) continue;
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (std::equal(std::begin(own.v), std::end(own.v), std::begin(ep->participant_key.v))) {
        continue;
      }
      const std::string topic = ep->topic_name;
      if (topic.rfind("rq/", 0) != 0 || !in_partition(ep->qos, participant.partition())) continue;
      if (std::string node = runtime::parameter_service_node(topic); !node.empty()) {
        nodes.insert(std::move(node));
      }
    }
    if (n > 0) dds_return_loan(subs.get(), samples, n);
    if (!wanted.empty() && nodes.count(wanted) != 0) break;
    if (stop_requested()) throw runtime::Error("interrupted");
  } while (Clock::now() < deadline);
  return {nodes.begin(), nodes.end()};
}

std::string resolve_node(const runtime::dds::Participant& participant, const std::string& name,
                         std::chrono::milliseconds wait) {
  if (name.empty()) throw runtime::Error("empty node name");
  if (name.front() == '/') return name;
  const std::string exact = "/" + name;
  const auto nodes = discover_parameter_nodes(participant, wait, exact);
  std::vector<std::string> matches;
  for (const auto& node : nodes) {
    if (node == exact) return node;
    if (node.size() > exact.size() &&
        node.compare(node.size() - exact.size(), exact.size(), exact) == 0) {
      matches.push_back(node);
    }
  }
  if (matches.size() == 1) return matches.front();
  if (matches.empty()) {
    std::string seen;
    for (const auto& node : nodes) seen += (seen.empty() ? "" : ", ") + node;
    throw runtime::Error(
        "no node '" + name + "' offers parameter services" + where(participant) +
        "; nodes seen: " + (seen.empty() ? "none (is the graph running on this domain?)" : seen));
  }
  std::string all;
  for (const auto& node : matches) all += (all.empty() ? "" : ", ") + node;
  throw runtime::Error("'" + name + "' is ambiguous: " + all + " (give the full name)");
}

}  // namespace avs::cli
