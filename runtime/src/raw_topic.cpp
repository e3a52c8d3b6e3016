#include "avs/runtime/raw_topic.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>

#include "avs/runtime/sample.hpp"

namespace avs::runtime::dds {

namespace {

std::optional<Duration> finite(dds_duration_t d) {
  if (d == DDS_INFINITY) return std::nullopt;
  return Duration(d);
}

dds_duration_t dds_duration(const std::optional<Duration>& d) {
  return d ? d->count() : DDS_INFINITY;
}

}  // namespace

EndpointQos EndpointQos::from_dds(const dds_qos_t* qos) {
  EndpointQos q;
  if (qos == nullptr) return q;
  dds_reliability_kind_t reliability;
  dds_duration_t blocking;
  if (dds_qget_reliability(qos, &reliability, &blocking)) {
    q.reliable = reliability == DDS_RELIABILITY_RELIABLE;
  }
  dds_durability_kind_t durability;
  if (dds_qget_durability(qos, &durability)) {
    q.transient_local = durability != DDS_DURABILITY_VOLATILE;
  }
  dds_history_kind_t history;
  std::int32_t depth = 0;
  if (dds_qget_history(qos, &history, &depth)) {
    q.keep_all = history == DDS_HISTORY_KEEP_ALL;
    q.depth = depth;
  }
  dds_duration_t d;
  if (dds_qget_deadline(qos, &d)) q.deadline = finite(d);
  if (dds_qget_lifespan(qos, &d)) q.lifespan = finite(d);
  dds_liveliness_kind_t liveliness;
  if (dds_qget_liveliness(qos, &liveliness, &d)) {
    q.liveliness_automatic = liveliness == DDS_LIVELINESS_AUTOMATIC;
    q.liveliness_lease = finite(d);
  }
  return q;
}

EndpointQos EndpointQos::from_profile(const QosProfile& profile) {
  EndpointQos q;
  q.reliable = profile.reliability == Reliability::reliable;
  q.transient_local = profile.durability == Durability::transient_local;
  q.depth = static_cast<std::int32_t>(profile.depth);
  q.deadline = profile.deadline;
  return q;
}

QosProfile EndpointQos::to_profile() const {
  QosProfile p;
  p.reliability = reliable ? Reliability::reliable : Reliability::best_effort;
  p.durability = transient_local ? Durability::transient_local : Durability::volatile_;
  p.depth = static_cast<std::uint32_t>(
      std::max<std::int32_t>(1, keep_all ? std::max(depth, 1000) : depth));
  p.deadline = deadline;
  return p;
}

Qos EndpointQos::to_dds() const {
  QosProfile base;  // only to get an owned dds_qos_t; every policy below is set explicitly
  Qos qos(base);
  dds_qset_reliability(qos.get(), reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  dds_qset_durability(qos.get(),
                      transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos.get(), keep_all ? DDS_HISTORY_KEEP_ALL : DDS_HISTORY_KEEP_LAST,
                   keep_all ? 0 : std::max(depth, 1));
  dds_qset_deadline(qos.get(), dds_duration(deadline));
  dds_qset_lifespan(qos.get(), dds_duration(lifespan));
  dds_qset_liveliness(
      qos.get(), liveliness_automatic ? DDS_LIVELINESS_AUTOMATIC : DDS_LIVELINESS_MANUAL_BY_TOPIC,
      dds_duration(liveliness_lease));
  return qos;
}

std::string EndpointQos::describe() const {
  std::string s = reliable ? "reliable" : "best_effort";
  s += transient_local ? ", transient_local" : ", volatile";
  s += keep_all ? ", keep_all" : ", keep_last " + std::to_string(depth);
  if (deadline) s += ", deadline " + std::to_string(deadline->count() / 1000) + " us";
  return s;
}

EndpointDiscovery::EndpointDiscovery(const Participant& participant, EndpointKinds kinds) {
  if (kinds != EndpointKinds::readers) {
    publications_ = Entity(check_dds(
        dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
        "read DCPSPublication"));
  }
  if (kinds != EndpointKinds::writers) {
    subscriptions_ = Entity(check_dds(
        dds_create_reader(participant.get(), DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr),
        "read DCPSSubscription"));
  }
  dds_guid_t own{};
  check_dds(dds_get_guid(participant.get(), &own), "participant guid");
  std::copy(std::begin(own.v), std::end(own.v), own_.begin());
}

std::vector<DiscoveredEndpoint> EndpointDiscovery::update() {
  std::vector<DiscoveredEndpoint> appeared;
  if (publications_) take(publications_.get(), true, appeared);
  if (subscriptions_) take(subscriptions_.get(), false, appeared);
  return appeared;
}

void EndpointDiscovery::take(dds_entity_t reader, bool is_writer,
                             std::vector<DiscoveredEndpoint>& appeared) {
  const char* what = is_writer ? "take DCPSPublication" : "take DCPSSubscription";
  for (;;) {
    constexpr int kBatch = 64;
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const int n = check_dds(dds_take(reader, samples, infos, kBatch, kBatch), what);
    for (int i = 0; i < n; ++i) {
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      Key key{{}, is_writer};
      std::copy(std::begin(ep->key.v), std::end(ep->key.v), key.first.begin());
      if (infos[i].instance_state != DDS_IST_ALIVE) {
        endpoints_.erase(key);  // an invalid sample still carries the key
        continue;
      }
      if (!infos[i].valid_data) continue;
      if (std::equal(own_.begin(), own_.end(), std::begin(ep->participant_key.v))) continue;
      const std::string topic = ep->topic_name;
      if (topic.rfind("DCPS", 0) == 0) continue;
      DiscoveredEndpoint e;
      e.is_writer = is_writer;
      e.key = key.first;
      std::copy(std::begin(ep->participant_key.v), std::end(ep->participant_key.v),
                e.participant.begin());
      e.topic = topic;
      e.type_name = ep->type_name != nullptr ? ep->type_name : "";
      dds_qos_t* copy = dds_create_qos();
      if (ep->qos != nullptr) dds_copy_qos(copy, ep->qos);
      e.qos = std::shared_ptr<const dds_qos_t>(
          copy, [](const dds_qos_t* q) { dds_delete_qos(const_cast<dds_qos_t*>(q)); });
      const bool is_new = endpoints_.count(key) == 0;
      endpoints_[key] = e;
      if (is_new) appeared.push_back(std::move(e));
    }
    if (n > 0) dds_return_loan(reader, samples, n);
    if (n < kBatch) break;
  }
}

PublicationDiscovery::PublicationDiscovery(const Participant& participant)
    : discovery_(participant, EndpointKinds::writers) {}

std::vector<DiscoveredPublication> PublicationDiscovery::poll() {
  std::vector<DiscoveredPublication> found;
  for (const DiscoveredEndpoint& e : discovery_.update()) {
    DiscoveredPublication p;
    p.topic = e.topic;
    p.type_name = e.type_name;
    p.key = e.key;
    p.qos = EndpointQos::from_dds(e.qos.get());
    found.push_back(std::move(p));
  }
  return found;
}

RawReader::RawReader(const Participant& participant, const msg::TypeEntry& type,
                     const std::string& dds_topic, const EndpointQos& qos,
                     std::string_view user_data)
    : topic_(dds_topic) {
  Qos q = qos.to_dds();
  participant.apply_partition(q.get());
  if (!user_data.empty()) dds_qset_userdata(q.get(), user_data.data(), user_data.size());
  topic_entity_ = Entity(check_dds(
      dds_create_topic(participant.get(), type.descriptor, dds_topic.c_str(), nullptr, nullptr),
      "create topic " + dds_topic + " (" + type.dds_name + ")"));
  reader_ =
      Entity(check_dds(dds_create_reader(participant.get(), topic_entity_.get(), q.get(), nullptr),
                       "create reader on " + dds_topic));
}

ReaderLoss RawReader::loss() const {
  dds_sample_lost_status_t lost{};
  dds_sample_rejected_status_t rejected{};
  check_dds(dds_get_sample_lost_status(reader_.get(), &lost), "sample lost status of " + topic_);
  check_dds(dds_get_sample_rejected_status(reader_.get(), &rejected),
            "sample rejected status of " + topic_);
  return {lost.total_count, rejected.total_count};
}

std::uint32_t RawReader::incompatible_writers() const {
  dds_requested_incompatible_qos_status_t s{};
  check_dds(dds_get_requested_incompatible_qos_status(reader_.get(), &s),
            "incompatible QoS of " + topic_);
  return s.total_count;
}

std::uint32_t RawReader::matched_writers() const {
  dds_subscription_matched_status_t s{};
  check_dds(dds_get_subscription_matched_status(reader_.get(), &s), "matched status of " + topic_);
  return s.current_count;
}

namespace {

/// Cyclone 0.10.2 has no public call that returns a topic's sertype (dds_get_entity_sertype
/// came later). Sertypes are interned per domain, so the serdata of one sample written
/// and taken on a private probe topic of the same type carries the very sertype every
/// topic of that type uses. Returns one reference.
const ddsi_sertype* probe_sertype(const Participant& participant, const msg::TypeEntry& type) {
  std::string name = std::string("avs_sertype_probe_") + type.dds_name;
  std::replace(name.begin(), name.end(), ':', '_');
  Entity topic(check_dds(
      dds_create_topic(participant.get(), type.descriptor, name.c_str(), nullptr, nullptr),
      "create probe topic for " + std::string(type.dds_name)));
  EndpointQos q;
  q.keep_all = true;
  const Qos qos = q.to_dds();
  Entity reader(check_dds(dds_create_reader(participant.get(), topic.get(), qos.get(), nullptr),
                          "create probe reader"));
  Entity writer(check_dds(dds_create_writer(participant.get(), topic.get(), qos.get(), nullptr),
                          "create probe writer"));
  void* sample = dds_alloc(type.sample_size);  // zeroed: empty strings and sequences
  const dds_return_t rc = dds_write(writer.get(), sample);
  dds_sample_free(sample, type.descriptor, DDS_FREE_ALL);
  check_dds(rc, "write probe sample of " + std::string(type.dds_name));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  for (;;) {
    ddsi_serdata* data = nullptr;
    dds_sample_info_t info;
    const dds_return_t n = dds_takecdr(reader.get(), &data, 1, &info, DDS_ANY_STATE);
    if (n > 0) {
      const ddsi_sertype* sertype = ddsi_sertype_ref(data->type);
      ddsi_serdata_unref(data);
      return sertype;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      throw Error("no probe sample of " + std::string(type.dds_name) +
                  " came back within 2 s: cannot find its Cyclone sertype");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace

RawWriter::RawWriter(const Participant& participant, const msg::TypeEntry& type,
                     const std::string& dds_topic, const EndpointQos& qos)
    : topic_(dds_topic) {
  topic_entity_ = Entity(check_dds(
      dds_create_topic(participant.get(), type.descriptor, dds_topic.c_str(), nullptr, nullptr),
      "create topic " + dds_topic + " (" + type.dds_name + ")"));
  Qos q = qos.to_dds();
  dds_qset_ignorelocal(q.get(), DDS_IGNORELOCAL_PARTICIPANT);
  participant.apply_partition(q.get());
  writer_ =
      Entity(check_dds(dds_create_writer(participant.get(), topic_entity_.get(), q.get(), nullptr),
                       "create writer on " + dds_topic));
  sertype_ = probe_sertype(participant, type);
}

RawWriter::~RawWriter() {
  writer_.reset();
  topic_entity_.reset();
  if (sertype_ != nullptr) ddsi_sertype_unref(const_cast<ddsi_sertype*>(sertype_));
}

void RawWriter::write(std::span<const std::byte> cdr) {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::byte*>(cdr.data());
  iov.iov_len = static_cast<ddsrt_iov_len_t>(cdr.size());
  ddsi_serdata* data = ddsi_serdata_from_ser_iov(sertype_, SDK_DATA, 1, &iov, cdr.size());
  if (data == nullptr) {
    throw Error("write to " + topic_ + ": Cyclone refused " + std::to_string(cdr.size()) +
                " serialised bytes (bad CDR encapsulation header?)");
  }
  // dds_writecdr takes over the reference.
  check_dds(dds_writecdr(writer_.get(), data), "write serialised sample to " + topic_);
}

std::uint32_t RawWriter::matched_readers() const {
  dds_publication_matched_status_t status{};
  check_dds(dds_get_publication_matched_status(writer_.get(), &status),
            "matched status of " + topic_);
  return status.current_count;
}

CdrCodec::CdrCodec(const Participant& participant, const msg::TypeEntry& type)
    : type_(type), sertype_(probe_sertype(participant, type)) {}

CdrCodec::~CdrCodec() {
  ddsi_sertype_unref(const_cast<ddsi_sertype*>(sertype_));
}

std::shared_ptr<void> CdrCodec::to_sample(std::span<const std::byte> cdr) const {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::byte*>(cdr.data());
  iov.iov_len = static_cast<ddsrt_iov_len_t>(cdr.size());
  // Cyclone checks the bytes against the type here (lengths, bounds) and refuses bad ones.
  ddsi_serdata* data = ddsi_serdata_from_ser_iov(sertype_, SDK_DATA, 1, &iov, cdr.size());
  if (data == nullptr) {
    throw Error("Cyclone refused " + std::to_string(cdr.size()) + " serialised bytes as " +
                type_.dds_name + " (bad encapsulation header, truncated or malformed CDR)");
  }
  std::shared_ptr<void> sample = make_sample(type_.descriptor, type_.sample_size);
  const bool ok = ddsi_serdata_to_sample(data, sample.get(), nullptr, nullptr);
  ddsi_serdata_unref(data);
  if (!ok) {
    throw Error("cannot deserialise " + std::to_string(cdr.size()) + " bytes as " + type_.dds_name);
  }
  return sample;
}

std::vector<std::byte> CdrCodec::to_cdr(const void* sample) const {
  ddsi_serdata* data = ddsi_serdata_from_sample(sertype_, SDK_DATA, sample);
  if (data == nullptr) throw Error(std::string("cannot serialise a sample of ") + type_.dds_name);
  std::vector<std::byte> out(ddsi_serdata_size(data));
  ddsi_serdata_to_ser(data, 0, out.size(), out.data());
  ddsi_serdata_unref(data);
  return out;
}

}  // namespace avs::runtime::dds
