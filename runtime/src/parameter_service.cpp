// The container's parameter services (parameter_service.hpp). One thread waits on every
// request reader; a request is answered once the reply writer has matched a reader of the
// requester's participant (as rmw_cyclonedds's services do), so that no reply goes to nobody.
#include "parameter_service.hpp"

#include <atomic>
#include <chrono>
#include <cstring>
#include <deque>
#include <thread>

#include "avs/runtime/logger.hpp"
#include "avs/runtime/parameter_messages.hpp"

namespace avs::runtime {

namespace rcl = msgs::rcl_interfaces;

namespace {

/// One service of one node: its request reader and reply writer.
struct Endpoint {
  ParameterNode* node = nullptr;
  std::string service;
  const dds_topic_descriptor_t* request_descriptor = nullptr;
  std::size_t request_size = 0;
  std::unique_ptr<dds::Topic> request_topic;
  std::unique_ptr<dds::Topic> reply_topic;
  std::unique_ptr<dds::Reader> reader;
  std::unique_ptr<dds::Writer> writer;
  dds::Entity condition;
  std::function<void(Endpoint&, std::shared_ptr<void>)> handle;
};

/// A request taken from DDS, waiting for the requester's reply reader to be matched.
struct Pending {
  Endpoint* endpoint;
  std::shared_ptr<void> request;
  dds_instance_handle_t publication;
  std::chrono::steady_clock::time_point received;
};

/// The reply of `request`: its header (client id and sequence number) repeated.
template <class Response, class Request>
std::shared_ptr<Response> reply_to(const Request& request) {
  auto response = make_sample<Response>();
  response->client_guid = request.client_guid;
  response->sequence_number = request.sequence_number;
  return response;
}

std::string names_of(const ComponentSpec& spec) {
  std::string names;
  for (const auto& p : spec.parameters) names += (names.empty() ? "" : ", ") + p.name;
  return names.empty() ? "none" : names;
}

/// Why `message` cannot become parameter `name` of `node`, or "" with `out` set.
std::string check_change(const ParameterNode& node, const std::string& name,
                         const rcl::ParameterValue& message, ParamValue& out) {
  const ComponentSpec& spec = node.node_spec();
  const ParamSpec* p = spec.find_parameter(name);
  if (p == nullptr) {
    return "unknown parameter '" + name + "' of " + node.node_name() + " (" + spec.type +
           " has: " + names_of(spec) + ")";
  }
  if (!p->dynamic) {
    return name + " is not dynamic: " + spec.type +
           " reads it when it starts; change it in the graph's parameters and restart the "
           "container";
  }
  const auto type = static_cast<RosParameterType>(message.type);
  if (type == RosParameterType::not_set) return name + ": parameters cannot be deleted";
  auto value = from_message(message);
  if (!value) {
    return name + ": a " + to_string(type) + " value is not accepted, expected a " +
           to_string(p->type);
  }
  if (const std::string problem = p->check(*value); !problem.empty()) {
    return name + ": " + problem;
  }
  if (p->type == ParamType::real && std::holds_alternative<std::int64_t>(*value)) {
    value = static_cast<double>(std::get<std::int64_t>(*value));
  }
  out = std::move(*value);
  return {};
}

}  // namespace

struct ParameterService::Impl {
  Impl(const dds::Participant& p, std::vector<ParameterNode*> n, std::function<Time()> c)
      : participant(p), nodes(std::move(n)), clock(std::move(c)), log("parameters") {}

  template <class Request, class Response>
  void add(ParameterNode& node, const char* service,
           std::function<void(Endpoint&, std::shared_ptr<void>)> handle);
  void create_endpoints();
  void run();
  bool reply_reader_matched(const Endpoint& endpoint, dds_instance_handle_t publication) const;
  void take(Endpoint& endpoint);

  void handle_get(Endpoint& ep, std::shared_ptr<void> sample);
  void handle_types(Endpoint& ep, std::shared_ptr<void> sample);
  void handle_list(Endpoint& ep, std::shared_ptr<void> sample);
  void handle_describe(Endpoint& ep, std::shared_ptr<void> sample);
  void handle_set(Endpoint& ep, std::shared_ptr<void> sample);
  void publish_event(const ParameterNode& node, const ParameterValues& values,
                     const std::vector<std::string>& changed);

  const dds::Participant& participant;
  std::vector<ParameterNode*> nodes;
  std::function<Time()> clock;
  Logger log;
  std::vector<std::unique_ptr<Endpoint>> endpoints;
  std::unique_ptr<dds::Topic> events_topic;
  std::unique_ptr<dds::Writer> events_writer;
  std::unique_ptr<dds::WaitSet> waitset;
  std::deque<Pending> pending;
  std::atomic<bool> stopping{false};
  std::thread thread;
};

template <class Request, class Response>
void ParameterService::Impl::add(ParameterNode& node, const char* service,
                                 std::function<void(Endpoint&, std::shared_ptr<void>)> handle) {
  auto ep = std::make_unique<Endpoint>();
  ep->node = &node;
  ep->service = service;
  ep->request_descriptor = msg::TypeSupport<Request>::descriptor();
  ep->request_size = sizeof(Request);
  const QosProfile qos = service_qos();
  ep->request_topic = std::make_unique<dds::Topic>(
      participant, ep->request_descriptor, parameter_request_topic(node.node_name(), service), qos);
  ep->reply_topic =
      std::make_unique<dds::Topic>(participant, msg::TypeSupport<Response>::descriptor(),
                                   parameter_reply_topic(node.node_name(), service), qos);
  ep->reader = std::make_unique<dds::Reader>(participant, *ep->request_topic, qos);
  ep->writer = std::make_unique<dds::Writer>(participant, *ep->reply_topic, qos);
  ep->condition = dds::Entity(check_dds(dds_create_readcondition(ep->reader->get(), DDS_ANY_STATE),
                                        "read condition on " + ep->request_topic->name()));
  ep->handle = std::move(handle);
  endpoints.push_back(std::move(ep));
}

void ParameterService::Impl::create_endpoints() {
  using namespace std::placeholders;
  for (ParameterNode* node : nodes) {
    add<rcl::GetParameters_Request, rcl::GetParameters_Response>(
        *node, "get_parameters", std::bind(&Impl::handle_get, this, _1, _2));
    add<rcl::SetParameters_Request, rcl::SetParameters_Response>(
        *node, "set_parameters", std::bind(&Impl::handle_set, this, _1, _2));
    add<rcl::ListParameters_Request, rcl::ListParameters_Response>(
        *node, "list_parameters", std::bind(&Impl::handle_list, this, _1, _2));
    add<rcl::DescribeParameters_Request, rcl::DescribeParameters_Response>(
        *node, "describe_parameters", std::bind(&Impl::handle_describe, this, _1, _2));
    add<rcl::GetParameterTypes_Request, rcl::GetParameterTypes_Response>(
        *node, "get_parameter_types", std::bind(&Impl::handle_types, this, _1, _2));
  }
  events_topic =
      std::make_unique<dds::Topic>(participant, msg::TypeSupport<rcl::ParameterEvent>::descriptor(),
                                   kParameterEventsTopic, parameter_events_qos());
  events_writer = std::make_unique<dds::Writer>(participant, *events_topic, parameter_events_qos());
  waitset = std::make_unique<dds::WaitSet>(participant);
  for (std::size_t i = 0; i < endpoints.size(); ++i) {
    waitset->attach(endpoints[i]->condition.get(), static_cast<dds_attach_t>(i + 1));
  }
}

namespace {

/// The `clientid=...;` of an endpoint's USER_DATA: rmw_cyclonedds puts the same id on a
/// client's request writer and its reply reader, so that a service answers only once the
/// reader of *that* client has matched (one ros2 process holds several clients). Empty: none.
std::string client_id(const dds_qos_t* qos) {
  void* data = nullptr;
  std::size_t size = 0;
  if (qos == nullptr || !dds_qget_userdata(qos, &data, &size) || data == nullptr) return {};
  const std::string text(static_cast<const char*>(data), size);
  dds_free(data);
  const std::string key = "clientid=";
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return {};
  const std::size_t end = text.find(';', at);
  return text.substr(at + key.size(),
                     end == std::string::npos ? std::string::npos : end - at - key.size());
}

}  // namespace

bool ParameterService::Impl::reply_reader_matched(const Endpoint& endpoint,
                                                  dds_instance_handle_t publication) const {
  dds_builtintopic_endpoint_t* writer =
      dds_get_matched_publication_data(endpoint.reader->get(), publication);
  if (writer == nullptr) return true;  // the requester is gone or unknown: do not wait for it
  const dds_guid_t requester = writer->participant_key;
  const std::string client = client_id(writer->qos);
  dds_builtintopic_free_endpoint(writer);
  constexpr std::size_t kMax = 256;
  dds_instance_handle_t readers[kMax];
  const dds_return_t n = dds_get_matched_subscriptions(endpoint.writer->get(), readers, kMax);
  for (dds_return_t i = 0; i < n && static_cast<std::size_t>(i) < kMax; ++i) {
    dds_builtintopic_endpoint_t* reader =
        dds_get_matched_subscription_data(endpoint.writer->get(), readers[i]);
    if (reader == nullptr) continue;
    // With a client id (ROS 2 clients): that client's reply reader; without (avs, plain DDS
    // requesters): any reply reader of the requesting participant.
    const bool same = client.empty() ? std::memcmp(reader->participant_key.v, requester.v,
                                                   sizeof requester.v) == 0
                                     : client_id(reader->qos) == client;
    dds_builtintopic_free_endpoint(reader);
    if (same) return true;
  }
  return false;
}

void ParameterService::Impl::take(Endpoint& endpoint) {
  for (;;) {
    auto sample = make_sample(endpoint.request_descriptor, endpoint.request_size);
    void* buffers[1] = {sample.get()};
    dds_sample_info_t info;
    const dds_return_t taken = dds_take(endpoint.reader->get(), buffers, &info, 1, 1);
    if (taken <= 0) return;
    if (!info.valid_data) continue;
    pending.push_back(
        {&endpoint, std::move(sample), info.publication_handle, std::chrono::steady_clock::now()});
  }
}

void ParameterService::Impl::run() {
  std::vector<dds_attach_t> triggered(endpoints.size() + 1);
  while (!stopping) {
    const dds_duration_t timeout = pending.empty() ? DDS_MSECS(100) : DDS_MSECS(5);
    const int n = waitset->wait(triggered.data(), triggered.size(), timeout);
    for (int i = 0; i < n; ++i) {
      const auto token = triggered[static_cast<std::size_t>(i)];
      if (token != 0) take(*endpoints[static_cast<std::size_t>(token - 1)]);
    }
    // Answer what can be answered; a requester whose reply reader is still unmatched after
    // 2 s gets its reply anyway (it may be a client that does not read replies).
    const auto now = std::chrono::steady_clock::now();
    for (std::size_t k = pending.size(); k > 0; --k) {
      Pending p = std::move(pending.front());
      pending.pop_front();
      if (!reply_reader_matched(*p.endpoint, p.publication) &&
          now - p.received < std::chrono::seconds(2)) {
        pending.push_back(std::move(p));
        continue;
      }
      try {
        p.endpoint->handle(*p.endpoint, std::move(p.request));
      } catch (const std::exception& e) {
        log.error(p.endpoint->node->node_name(), " ", p.endpoint->service, ": ", e.what());
      }
    }
  }
}

void ParameterService::Impl::handle_get(Endpoint& ep, std::shared_ptr<void> sample) {
  const auto& request = *static_cast<const rcl::GetParameters_Request*>(sample.get());
  auto response = reply_to<rcl::GetParameters_Response>(request);
  const ParameterValues values = ep.node->snapshot();
  resize_sequence(response->values, request.names._length);
  for (std::uint32_t i = 0; i < request.names._length; ++i) {
    const std::string name(get_string(request.names._buffer[i]));
    if (values.contains(name)) to_message(values.all().at(name), response->values._buffer[i]);
  }
  ep.writer->write(response.get());
}

void ParameterService::Impl::handle_types(Endpoint& ep, std::shared_ptr<void> sample) {
  const auto& request = *static_cast<const rcl::GetParameterTypes_Request*>(sample.get());
  auto response = reply_to<rcl::GetParameterTypes_Response>(request);
  resize_sequence(response->types, request.names._length);
  for (std::uint32_t i = 0; i < request.names._length; ++i) {
    const ParamSpec* p = ep.node->node_spec().find_parameter(get_string(request.names._buffer[i]));
    response->types._buffer[i] =
        static_cast<std::uint8_t>(p ? ros_parameter_type(p->type) : RosParameterType::not_set);
  }
  ep.writer->write(response.get());
}

void ParameterService::Impl::handle_list(Endpoint& ep, std::shared_ptr<void> sample) {
  const auto& request = *static_cast<const rcl::ListParameters_Request*>(sample.get());
  auto response = reply_to<rcl::ListParameters_Response>(request);
  std::vector<std::string> names;
  for (const auto& p : ep.node->node_spec().parameters) {
    bool wanted = request.prefixes._length == 0;
    for (std::uint32_t i = 0; i < request.prefixes._length; ++i) {
      const std::string prefix(get_string(request.prefixes._buffer[i]));
      wanted = wanted || p.name == prefix || p.name.rfind(prefix + ".", 0) == 0;
    }
    if (wanted) names.push_back(p.name);
  }
  resize_sequence(response->result.names, static_cast<std::uint32_t>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    set_string(response->result.names._buffer[i], names[i]);
  }
  ep.writer->write(response.get());
}

void ParameterService::Impl::handle_describe(Endpoint& ep, std::shared_ptr<void> sample) {
  const auto& request = *static_cast<const rcl::DescribeParameters_Request*>(sample.get());
  auto response = reply_to<rcl::DescribeParameters_Response>(request);
  resize_sequence(response->descriptors, request.names._length);
  for (std::uint32_t i = 0; i < request.names._length; ++i) {
    const std::string_view name = get_string(request.names._buffer[i]);
    auto& descriptor = response->descriptors._buffer[i];
    if (const ParamSpec* p = ep.node->node_spec().find_parameter(name)) {
      to_descriptor(*p, descriptor);
    } else {
      set_string(descriptor.name, name);  // type 0: not set, the parameter does not exist
    }
  }
  ep.writer->write(response.get());
}

void ParameterService::Impl::handle_set(Endpoint& ep, std::shared_ptr<void> sample) {
  const auto& request = *static_cast<const rcl::SetParameters_Request*>(sample.get());
  ParameterNode& node = *ep.node;
  const std::uint32_t count = request.parameters._length;
  auto reasons = std::make_shared<std::vector<std::string>>(count);
  ParameterValues values = node.snapshot();
  std::vector<std::string> changed;
  std::vector<std::uint32_t> changed_index;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto& parameter = request.parameters._buffer[i];
    const std::string name(get_string(parameter.name));
    ParamValue value;
    (*reasons)[i] = check_change(node, name, parameter.value, value);
    if (!(*reasons)[i].empty()) continue;
    values.set(name, std::move(value));
    changed.push_back(name);
    changed_index.push_back(i);
  }
  auto respond = [this, &ep, sample, reasons, changed, changed_index,
                  values](const std::string& refusal) {
    const auto& req = *static_cast<const rcl::SetParameters_Request*>(sample.get());
    auto response = reply_to<rcl::SetParameters_Response>(req);
    for (const std::uint32_t i : changed_index) {
      // The reply names the parameter's node already (`avs param set: /matching refused ...`).
      if (!refusal.empty()) (*reasons)[i] = refusal;
    }
    resize_sequence(response->results, static_cast<std::uint32_t>(reasons->size()));
    for (std::size_t i = 0; i < reasons->size(); ++i) {
      response->results._buffer[i].successful = (*reasons)[i].empty();
      set_string(response->results._buffer[i].reason, (*reasons)[i]);
    }
    if (refusal.empty() && !changed.empty()) {
      for (const auto& name : changed) {
        log.info(ep.node->node_name(), ": ", name, " = ", to_string(values.all().at(name)));
      }
      publish_event(*ep.node, values, changed);
    }
    ep.writer->write(response.get());
  };
  if (changed.empty()) {
    respond("");
  } else {
    node.apply_later(std::move(values), std::move(changed), std::move(respond));
  }
}

void ParameterService::Impl::publish_event(const ParameterNode& node, const ParameterValues& values,
                                           const std::vector<std::string>& changed) {
  auto event = make_sample<rcl::ParameterEvent>();
  to_ros_time(clock(), event->stamp);
  set_string(event->node, node.node_name());
  resize_sequence(event->changed_parameters, static_cast<std::uint32_t>(changed.size()));
  for (std::size_t i = 0; i < changed.size(); ++i) {
    set_string(event->changed_parameters._buffer[i].name, changed[i]);
    to_message(values.all().at(changed[i]), event->changed_parameters._buffer[i].value);
  }
  events_writer->write(event.get());
}

ParameterService::ParameterService(const dds::Participant& participant,
                                   std::vector<ParameterNode*> nodes, std::function<Time()> clock)
    : impl_(std::make_unique<Impl>(participant, std::move(nodes), std::move(clock))) {
  impl_->create_endpoints();
}

ParameterService::~ParameterService() {
  stop();
}

std::vector<dds_entity_t> ParameterService::readers_of(const ParameterNode& node) const {
  std::vector<dds_entity_t> out;
  for (const auto& ep : impl_->endpoints) {
    if (ep->node == &node) out.push_back(ep->reader->get());
  }
  return out;
}

std::vector<dds_entity_t> ParameterService::writers_of(const ParameterNode& node) const {
  std::vector<dds_entity_t> out{impl_->events_writer->get()};
  for (const auto& ep : impl_->endpoints) {
    if (ep->node == &node) out.push_back(ep->writer->get());
  }
  return out;
}

void ParameterService::start() {
  if (impl_->thread.joinable()) return;
  impl_->thread = std::thread([this] {
    try {
      impl_->run();
    } catch (const std::exception& e) {
      impl_->log.error("parameter service stopped: ", e.what());
    }
  });
}

void ParameterService::stop() {
  impl_->stopping = true;
  if (impl_->waitset) impl_->waitset->wake();
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace avs::runtime
