// Every topic type the build knows, by DDS type name; generated from idl/ (cmake/AvsIdl.cmake).
#pragma once

#include <cstddef>
#include <span>
#include <string_view>

#include <dds/dds.h>

namespace avs::msg {

struct TypeEntry {
  const char* dds_name;  ///< e.g. "sensor_msgs::msg::dds_::Image_"
  const dds_topic_descriptor_t* descriptor;
  std::size_t sample_size;
};

struct IdlSource {
  const char* file_name;  ///< e.g. "sensor_msgs.idl"
  const char* text;       ///< the IDL as written in idl/
};

std::span<const TypeEntry> all_types();
std::span<const IdlSource> idl_sources();

/// The entry for a DDS type name, or nullptr.
inline const TypeEntry* find_type(std::string_view dds_name) {
  for (const auto& entry : all_types()) {
    if (dds_name == entry.dds_name) return &entry;
  }
  return nullptr;
}

}  // namespace avs::msg
