// QoS profiles, nameable in YAML, turned into Cyclone QoS objects.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <dds/dds.h>

#include "avs/runtime/time.hpp"

namespace avs::runtime {

enum class Reliability { reliable, best_effort };
enum class Durability { volatile_, transient_local };

/// The QoS policies avs exposes. Defaults follow ROS 2's "default" profile
/// (reliable, keep last 10, volatile).
struct QosProfile {
  Reliability reliability = Reliability::reliable;
  std::uint32_t depth = 10;  ///< KEEP_LAST depth
  Durability durability = Durability::volatile_;
  std::optional<Duration> deadline;

  friend bool operator==(const QosProfile&, const QosProfile&) = default;

  /// Named profiles usable in YAML: default, sensor_data, reliable, transient_local, clock.
  static std::optional<QosProfile> named(std::string_view name);
  std::string describe() const;
};

/// Owns a dds_qos_t.
class Qos {
 public:
  explicit Qos(const QosProfile& profile);
  const dds_qos_t* get() const { return qos_.get(); }
  dds_qos_t* get() { return qos_.get(); }

 private:
  struct Deleter {
    void operator()(dds_qos_t* q) const { dds_delete_qos(q); }
  };
  std::unique_ptr<dds_qos_t, Deleter> qos_;
};

}  // namespace avs::runtime
