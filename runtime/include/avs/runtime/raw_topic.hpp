// Serialised (CDR) access to topics of any type this build knows, for tools that store and
// replay samples without decoding them (`avs bag`): discovery of remote publications with
// their offered QoS, readers handing out Cyclone's serdata as received, and writers that
// publish CDR bytes as they are (no deserialise/serialise round trip either way).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include "avs/msg/type_registry.hpp"
#include "avs/runtime/dds.hpp"
#include "avs/runtime/time.hpp"

namespace avs::runtime::dds {

/// The QoS policies an endpoint offers or requests, as far as recording and replay need them
/// (the ones ROS 2 stores in rosbag2's `offered_qos_profiles`).
struct EndpointQos {
  bool reliable = true;
  bool transient_local = false;
  bool keep_all = false;
  std::int32_t depth = 10;                   ///< KEEP_LAST depth (ignored with keep_all)
  std::optional<Duration> deadline;          ///< nullopt: infinite
  std::optional<Duration> lifespan;          ///< nullopt: infinite
  bool liveliness_automatic = true;          ///< false: manual by participant/topic
  std::optional<Duration> liveliness_lease;  ///< nullopt: infinite

  /// From a Cyclone QoS object (policies it does not set keep their defaults above).
  static EndpointQos from_dds(const dds_qos_t* qos);
  /// A Cyclone QoS object with these policies.
  Qos to_dds() const;
  /// A component port's profile (reliability, durability, depth, deadline) as an endpoint's.
  static EndpointQos from_profile(const QosProfile& profile);
  /// The component port profile closest to these policies (keep-all becomes a keep-last
  /// depth of at least 1000; lifespan and liveliness have no place in a port profile).
  QosProfile to_profile() const;
  /// "reliable, volatile, keep_last 10" (for messages).
  std::string describe() const;
};

/// The USER_DATA of a recorder's readers (`avs bag record`): writers of a lockstep graph wait
/// for readers that carry it (runtime/src/recorder_acks.hpp).
inline constexpr std::string_view kRecorderUserData = "avs.recorder;";

/// One remote reader or writer, as DDS discovery (the DCPSPublication and DCPSSubscription
/// built-in topics) shows it.
struct DiscoveredEndpoint {
  bool is_writer = true;
  std::array<std::uint8_t, 16> key{};          ///< the endpoint's GUID
  std::array<std::uint8_t, 16> participant{};  ///< its participant's GUID
  std::string topic;                           ///< DDS name, e.g. "rt/chatter"
  std::string type_name;                       ///< DDS type name
  std::shared_ptr<const dds_qos_t> qos;        ///< a copy of its QoS (never null)
};

enum class EndpointKinds { writers, readers, both };

/// Follows DDS discovery: every alive endpoint of other participants, Cyclone's own DCPS*
/// topics left out (the one place `avs topic`, `avs node`, `avs graph live` and the recorder
/// read discovery from).
class EndpointDiscovery {
 public:
  using Key = std::pair<std::array<std::uint8_t, 16>, bool>;  ///< (GUID, is_writer)

  explicit EndpointDiscovery(const Participant& participant,
                             EndpointKinds kinds = EndpointKinds::both);
  /// Takes what discovery learned since the last call: returns the endpoints that appeared;
  /// those gone (disposed, their participant lost) leave endpoints().
  std::vector<DiscoveredEndpoint> update();
  const std::map<Key, DiscoveredEndpoint>& endpoints() const { return endpoints_; }
  /// The DCPSPublication reader (attach a read condition to a waitset to wake on news);
  /// 0 without writers.
  dds_entity_t publication_reader() const { return publications_.get(); }

 private:
  void take(dds_entity_t reader, bool is_writer, std::vector<DiscoveredEndpoint>& appeared);

  Entity publications_, subscriptions_;
  std::array<std::uint8_t, 16> own_{};
  std::map<Key, DiscoveredEndpoint> endpoints_;
};

/// One remote data writer, as seen on the DCPSPublication built-in topic.
struct DiscoveredPublication {
  std::string topic;                   ///< DDS name, e.g. "rt/chatter"
  std::string type_name;               ///< DDS type name, e.g. "std_msgs::msg::dds_::String_"
  std::array<std::uint8_t, 16> key{};  ///< the writer's GUID
  EndpointQos qos;
};

/// Follows the DCPSPublication built-in topic: poll() returns the writers that appeared
/// since the last call, skipping the participant's own and Cyclone's built-in (DCPS*) topics.
class PublicationDiscovery {
 public:
  explicit PublicationDiscovery(const Participant& participant);
  std::vector<DiscoveredPublication> poll();
  /// The built-in reader (attach its status/read condition to a waitset to wake on news).
  dds_entity_t reader() const { return discovery_.publication_reader(); }

 private:
  EndpointDiscovery discovery_;
};

/// Totals of samples a reader knows it did not get (cumulative since creation).
struct ReaderLoss {
  std::uint64_t lost = 0;      ///< DDS SAMPLE_LOST: gaps seen in the writer's sequence
  std::uint64_t rejected = 0;  ///< DDS SAMPLE_REJECTED: no room in the reader history
};

/// A reader that hands out serialised samples (Cyclone serdata, one reference each).
class RawReader {
 public:
  /// `user_data`: the reader's USER_DATA QoS (e.g. kRecorderUserData); empty: none.
  RawReader(const Participant& participant, const msg::TypeEntry& type,
            const std::string& dds_topic, const EndpointQos& qos, std::string_view user_data = {});

  /// Takes up to `max` samples; for each valid one calls `fn(serdata, info)`. `fn` receives
  /// a serdata reference it owns (keep it, or release it with ddsi_serdata_unref). Returns
  /// the number of samples taken (invalid ones included).
  template <class Fn>
  int take(std::uint32_t max, Fn&& fn) {
    constexpr std::uint32_t kBatch = 64;
    int total = 0;
    while (max > 0) {
      ddsi_serdata* data[kBatch];
      dds_sample_info_t infos[kBatch];
      const std::uint32_t want = max < kBatch ? max : kBatch;
      const dds_return_t n = dds_takecdr(reader_.get(), data, want, infos, DDS_ANY_STATE);
      if (n < 0) check_dds(n, "take serialised samples from " + topic_);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        if (infos[i].valid_data) {
          fn(data[i], infos[i]);
        } else {
          ddsi_serdata_unref(data[i]);
        }
      }
      total += n;
      max -= static_cast<std::uint32_t>(n);
      if (static_cast<std::uint32_t>(n) < want) break;
    }
    return total;
  }

  dds_entity_t get() const { return reader_.get(); }
  const std::string& topic() const { return topic_; }
  ReaderLoss loss() const;
  /// Writers this reader could not match because of incompatible QoS (cumulative).
  std::uint32_t incompatible_writers() const;
  std::uint32_t matched_writers() const;

 private:
  std::string topic_;
  Entity topic_entity_;
  Entity reader_;
};

/// Converts between serialised samples (CDR, the 4-byte encapsulation header included) and
/// samples of the C type, for a type known only at run time: what a container does for
/// components that deal in serialised samples (bag_player, bag_recorder). Uses the type's
/// Cyclone sertype, so the bytes are exactly what a DDS writer of that type would send.
class CdrCodec {
 public:
  CdrCodec(const Participant& participant, const msg::TypeEntry& type);
  ~CdrCodec();
  CdrCodec(const CdrCodec&) = delete;
  CdrCodec& operator=(const CdrCodec&) = delete;

  /// A sample (freed with everything it holds) from serialised bytes. Throws Error naming
  /// the type when Cyclone refuses them (bad header, truncated, out-of-range lengths).
  std::shared_ptr<void> to_sample(std::span<const std::byte> cdr) const;
  /// The serialised bytes of a sample of the type.
  std::vector<std::byte> to_cdr(const void* sample) const;
  const msg::TypeEntry& type() const { return type_; }

 private:
  const msg::TypeEntry& type_;
  const ddsi_sertype* sertype_ = nullptr;  ///< one reference, released in the destructor
};

/// A writer that publishes serialised samples (the 4-byte encapsulation header included),
/// exactly as given: Cyclone's serdata is built from the bytes and written with
/// dds_writecdr (source timestamp = time of writing).
class RawWriter {
 public:
  RawWriter(const Participant& participant, const msg::TypeEntry& type,
            const std::string& dds_topic, const EndpointQos& qos);
  ~RawWriter();
  RawWriter(const RawWriter&) = delete;
  RawWriter& operator=(const RawWriter&) = delete;

  /// Throws Error when Cyclone refuses the bytes (bad encapsulation header) or the write fails.
  void write(std::span<const std::byte> cdr);
  std::uint32_t matched_readers() const;
  dds_entity_t get() const { return writer_.get(); }
  const std::string& topic() const { return topic_; }

 private:
  std::string topic_;
  Entity topic_entity_;
  Entity writer_;
  const ddsi_sertype* sertype_ = nullptr;  ///< one reference, released in the destructor
};

}  // namespace avs::runtime::dds
