#include "avs/runtime/qos.hpp"

#include "avs/runtime/error.hpp"

namespace avs::runtime {

std::optional<QosProfile> QosProfile::named(std::string_view name) {
  QosProfile p;
  if (name == "default" || name == "reliable") return p;
  if (name == "sensor_data") {  // ROS 2's rmw_qos_profile_sensor_data
    p.reliability = Reliability::best_effort;
    p.depth = 5;
    return p;
  }
  if (name == "transient_local") {
    p.durability = Durability::transient_local;
    p.depth = 1;
    return p;
  }
  if (name == "clock") {  // ROS 2's /clock: best effort, keep last 1
    p.reliability = Reliability::best_effort;
    p.depth = 1;
    return p;
  }
  return std::nullopt;
}

std::string QosProfile::describe() const {
  std::string s = reliability == Reliability::reliable ? "reliable" : "best_effort";
  s += ", keep_last " + std::to_string(depth);
  s += durability == Durability::volatile_ ? ", volatile" : ", transient_local";
  if (deadline) s += ", deadline " + std::to_string(deadline->count() / 1000) + " us";
  return s;
}

Qos::Qos(const QosProfile& profile) : qos_(dds_create_qos()) {
  if (!qos_) throw Error("dds_create_qos failed");
  dds_qset_reliability(qos_.get(),
                       profile.reliability == Reliability::reliable ? DDS_RELIABILITY_RELIABLE
                                                                    : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_SECS(1));
  dds_qset_history(qos_.get(), DDS_HISTORY_KEEP_LAST, static_cast<int32_t>(profile.depth));
  dds_qset_durability(qos_.get(), profile.durability == Durability::volatile_
                                      ? DDS_DURABILITY_VOLATILE
                                      : DDS_DURABILITY_TRANSIENT_LOCAL);
  if (profile.deadline) dds_qset_deadline(qos_.get(), profile.deadline->count());
  // ROS 2 interop: plain CDR (XCDR1) only, see ../shared/reference/ros2-messages-and-mcap.md.
  dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos_.get(), 1, &xcdr1);
}

}  // namespace avs::runtime
