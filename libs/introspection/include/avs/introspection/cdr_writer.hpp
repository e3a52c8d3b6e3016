// Encoding a sample of any type in the TypeDatabase from YAML (`avs topic pub`): the inverse of
// decode_cdr, XCDR1 little endian with the 4-byte encapsulation header, as DDS sends it.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "avs/introspection/type_database.hpp"

namespace avs::introspection {

/// A YAML value that does not fit the type; what() names the field path and what was expected
/// ("data: expected true or false, got 'maybe'").
class EncodeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The serialised sample of `dds_name` whose fields `yaml` gives as a mapping (a null node or
/// `{}`: every field zero / empty). Fields left out are zero, empty strings and sequences;
/// unknown fields, wrong kinds, out-of-range integers, over-long bounded strings and sequences
/// and wrong array lengths throw EncodeError. Byte sequences are lists of integers.
std::vector<std::uint8_t> encode_cdr(const TypeDatabase& database, std::string_view dds_name,
                                     const YAML::Node& yaml);

}  // namespace avs::introspection
