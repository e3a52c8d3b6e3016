// Test helper: serialise a C sample with Cyclone itself (write, then take the serialised
// form back with dds_takecdr), so the CDR reader is checked against the real encoder.
#pragma once

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include "avs/msg/type_support.hpp"

namespace avs::introspection::test {

class CycloneSerializer {
 public:
  CycloneSerializer() : participant_(dds_create_participant(DDS_DOMAIN_DEFAULT, nullptr, nullptr)) {
    if (participant_ < 0)
      throw std::runtime_error(std::string("create participant: ") + dds_strretcode(participant_));
  }
  ~CycloneSerializer() { dds_delete(participant_); }
  CycloneSerializer(const CycloneSerializer&) = delete;
  CycloneSerializer& operator=(const CycloneSerializer&) = delete;

  /// The bytes of `sample` as Cyclone puts them on the wire (encapsulation header first).
  template <class T>
  std::vector<std::uint8_t> serialize(const T& sample) {
    const std::string name = std::string("introspection_test/") + std::to_string(++topic_count_);
    const auto topic = check(dds_create_topic(participant_, avs::msg::TypeSupport<T>::descriptor(),
                                              name.c_str(), nullptr, nullptr),
                             "create topic");
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    const auto reader =
        check(dds_create_reader(participant_, topic, qos, nullptr), "create reader");
    const auto writer =
        check(dds_create_writer(participant_, topic, qos, nullptr), "create writer");
    dds_delete_qos(qos);
    check(dds_write(writer, &sample), "write");
    ddsi_serdata* serdata = nullptr;
    dds_sample_info_t info;
    for (int attempt = 0; attempt < 200; ++attempt) {  // local delivery is normally synchronous
      if (check(dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE), "takecdr") == 1) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (serdata == nullptr) throw std::runtime_error("no sample came back on " + name);
    std::vector<std::uint8_t> bytes(ddsi_serdata_size(serdata));
    ddsi_serdata_to_ser(serdata, 0, bytes.size(), bytes.data());
    ddsi_serdata_unref(serdata);
    dds_delete(writer);
    dds_delete(reader);
    dds_delete(topic);
    return bytes;
  }

 private:
  static dds_return_t check(dds_return_t rc, const char* what) {
    if (rc < 0) throw std::runtime_error(std::string(what) + ": " + dds_strretcode(rc));
    return rc;
  }

  dds_entity_t participant_;
  int topic_count_ = 0;
};

/// The one serialiser of a test program (one participant for all its cases).
inline CycloneSerializer& serializer() {
  static CycloneSerializer instance;
  return instance;
}

/// A C sequence viewing `values` (Cyclone only reads it while serialising).
template <class Sequence, class Element>
Sequence view(std::vector<Element>& values) {
  Sequence sequence{};
  sequence._maximum = sequence._length = static_cast<std::uint32_t>(values.size());
  sequence._buffer = values.data();
  sequence._release = false;
  return sequence;
}

inline char* text(const char* literal) {
  return const_cast<char*>(literal);
}

}  // namespace avs::introspection::test
