#include "avs/runtime/dds.hpp"

#include <cstdlib>

namespace avs::runtime::dds {

namespace {

// Cyclone's default writer history cache (WhcHigh 500 KiB) holds fewer than two 512x512
// images and throttles a 1 kHz image writer; 8 MB removed those stalls and losses
// (../shared/reference/dds-cyclone-notes.md). Used only when CYCLONEDDS_URI is not set.
constexpr const char* kDefaultConfig =
    "<CycloneDDS><Domain id=\"any\"><Internal><Watermarks><WhcHigh>8MB</WhcHigh></Watermarks>"
    "</Internal></Domain></CycloneDDS>";

dds_domainid_t prepare_domain(dds_domainid_t domain) {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri != nullptr && *uri != '\0') return domain;
  // The domain lives as long as the process, like Cyclone's implicit default domain; a
  // second participant in the same process finds it already created.
  const dds_entity_t created = dds_create_domain(domain, kDefaultConfig);
  if (created < 0 && created != DDS_RETCODE_PRECONDITION_NOT_MET) {
    check_dds(created, "create DDS domain " + std::to_string(domain));
  }
  return domain;
}

}  // namespace

namespace {
dds_entity_t create_participant(dds_domainid_t domain, const std::string& user_data) {
  dds_qos_t* qos = nullptr;
  if (!user_data.empty()) {
    qos = dds_create_qos();
    dds_qset_userdata(qos, user_data.data(), user_data.size());
  }
  const dds_entity_t p = dds_create_participant(prepare_domain(domain), qos, nullptr);
  if (qos != nullptr) dds_delete_qos(qos);
  return check_dds(p, "create DDS participant on domain " + std::to_string(domain));
}
}  // namespace

Participant::Participant(dds_domainid_t domain, std::string partition, const std::string& user_data)
    : Entity(create_participant(domain, user_data)), partition_(std::move(partition)) {}

void Participant::apply_partition(dds_qos_t* qos) const {
  if (!partition_.empty()) dds_qset_partition1(qos, partition_.c_str());
}

Topic::Topic(const Participant& participant, const dds_topic_descriptor_t* descriptor,
             const std::string& name, const QosProfile& qos)
    : Entity(check_dds(
          dds_create_topic(participant.get(), descriptor, name.c_str(), Qos(qos).get(), nullptr),
          "create topic " + name + " (" + descriptor->m_typename + ")")),
      name_(name) {}

namespace {
Qos endpoint_qos(const Participant& participant, const QosProfile& profile) {
  Qos qos(profile);
  participant.apply_partition(qos.get());
  // In-process delivery is done by the container without copies; DDS serves the others.
  dds_qset_ignorelocal(qos.get(), DDS_IGNORELOCAL_PARTICIPANT);
  return qos;
}
}  // namespace

Writer::Writer(const Participant& participant, const Topic& topic, const QosProfile& qos)
    : Entity(check_dds(dds_create_writer(participant.get(), topic.get(),
                                         endpoint_qos(participant, qos).get(), nullptr),
                       "create writer on " + topic.name())),
      topic_name_(topic.name()) {}

// The error's context is built only on failure: these run per sample, where a message string
// made every time was a heap allocation per frame (issue 16 section 3).
void Writer::write(const void* sample) {
  const dds_return_t rc = dds_write(get(), sample);
  if (rc < 0) check_dds(rc, "write to " + topic_name_);
}

std::uint32_t Writer::matched_readers() const {
  dds_publication_matched_status_t status{};
  const dds_return_t rc = dds_get_publication_matched_status(get(), &status);
  if (rc < 0) check_dds(rc, "matched status of " + topic_name_);
  return status.current_count;
}

Reader::Reader(const Participant& participant, const Topic& topic, const QosProfile& qos)
    : Entity(check_dds(dds_create_reader(participant.get(), topic.get(),
                                         endpoint_qos(participant, qos).get(), nullptr),
                       "create reader on " + topic.name())),
      topic_name_(topic.name()) {}

WaitSet::WaitSet(const Participant& participant)
    : Entity(check_dds(dds_create_waitset(participant.get()), "create waitset")),
      guard_(check_dds(dds_create_guardcondition(participant.get()), "create guard condition")) {
  attach(guard_.get(), 0);
}

void WaitSet::attach(dds_entity_t entity, dds_attach_t token) {
  check_dds(dds_waitset_attach(get(), entity, token), "attach to waitset");
}

void WaitSet::detach(dds_entity_t entity) {
  check_dds(dds_waitset_detach(get(), entity), "detach from waitset");
}

int WaitSet::wait(dds_attach_t* triggered, std::size_t capacity, dds_duration_t timeout) {
  const dds_return_t n = check_dds(dds_waitset_wait(get(), triggered, capacity, timeout), "wait");
  bool woken = false;
  check_dds(dds_take_guardcondition(guard_.get(), &woken), "reset guard condition");
  return n;
}

void WaitSet::wake() {
  check_dds(dds_set_guardcondition(guard_.get(), true), "wake waitset");
}

}  // namespace avs::runtime::dds
