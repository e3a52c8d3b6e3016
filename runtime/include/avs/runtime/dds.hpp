// Move-only RAII wrappers over Cyclone DDS's C API. Every return code is checked by
// check_dds() and turned into an Error that names the entity and topic.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include <dds/dds.h>

#include "avs/runtime/error.hpp"
#include "avs/runtime/qos.hpp"

namespace avs::runtime::dds {

/// Owns one DDS entity handle; deletes it (and its children) on destruction.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  ~Entity() { reset(); }

  dds_entity_t get() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }
  void reset() {
    if (handle_ > 0) dds_delete(handle_);  // never throws; errors at teardown are moot
    handle_ = 0;
  }

 private:
  dds_entity_t handle_ = 0;
};

/// Domain participant with the DDS partition of its readers and writers. Deployments keep
/// systems that share a network apart by partition (docs/deploy.md); empty: the default
/// partition. The domain and the partition come from the caller (a graph, a command-line
/// option), never from the environment: the command line reads AVS_DOMAIN_ID/AVS_PARTITION.
class Participant : public Entity {
 public:
  /// `user_data`: the participant's USER_DATA QoS, e.g. "enclave=/;" which ROS 2 (rmw_dds_common)
  /// needs to take the participant's nodes into its graph; empty: none.
  explicit Participant(dds_domainid_t domain = 0, std::string partition = {},
                       const std::string& user_data = {});
  const std::string& partition() const { return partition_; }
  /// Puts the partition into the QoS of a reader or writer of this participant (every
  /// endpoint of a user topic goes through this; built-in topic readers see all partitions).
  void apply_partition(dds_qos_t* qos) const;

 private:
  std::string partition_;
};

class Topic : public Entity {
 public:
  Topic(const Participant& participant, const dds_topic_descriptor_t* descriptor,
        const std::string& name, const QosProfile& qos);
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

/// Data writer. Samples from this writer are not delivered to readers of the same
/// participant (in-process delivery is the container's job).
class Writer : public Entity {
 public:
  Writer(const Participant& participant, const Topic& topic, const QosProfile& qos);
  void write(const void* sample);
  /// Number of matched readers in other participants.
  std::uint32_t matched_readers() const;
  const std::string& topic_name() const { return topic_name_; }

 private:
  std::string topic_name_;
};

/// Data reader, ignoring writers of the same participant (see Writer).
class Reader : public Entity {
 public:
  Reader(const Participant& participant, const Topic& topic, const QosProfile& qos);
  const std::string& topic_name() const { return topic_name_; }

 private:
  std::string topic_name_;
};

/// Wait set with a guard condition so another thread can wake it.
class WaitSet : public Entity {
 public:
  explicit WaitSet(const Participant& participant);
  void attach(dds_entity_t entity, dds_attach_t token);
  void detach(dds_entity_t entity);
  /// Waits up to `timeout`; returns the number of triggered entities.
  int wait(dds_attach_t* triggered, std::size_t capacity, dds_duration_t timeout);
  void wake();

 private:
  Entity guard_;
};

}  // namespace avs::runtime::dds
