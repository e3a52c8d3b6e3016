// Decoding serialised topic samples (XCDR1, as DDS and rosbag2 carry them) into a generic
// value tree, and printing that tree as YAML the way `ros2 topic echo` does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "avs/introspection/type_database.hpp"

namespace avs::introspection {

/// Malformed or truncated CDR; what() names the byte offset (from the start of the buffer,
/// encapsulation header included) and the field being read.
class CdrError : public std::runtime_error {
 public:
  CdrError(const std::string& message, std::size_t offset)
      : std::runtime_error(message), offset_(offset) {}
  std::size_t offset() const { return offset_; }

 private:
  std::size_t offset_;
};

/// One decoded value. Scalars keep their IDL type; uint8/octet sequences and arrays are
/// kept as raw bytes (an image is one `bytes` value, not 262144 children).
struct Value {
  enum class Kind : std::uint8_t { kBool, kInt, kUint, kFloat, kString, kBytes, kList, kStruct };

  Kind kind = Kind::kStruct;
  Primitive primitive = Primitive::kUint8;  ///< scalar type; element type for kBytes
  bool bool_value = false;
  std::int64_t int_value = 0;       ///< kInt (int8..int64)
  std::uint64_t uint_value = 0;     ///< kUint (uint8..uint64, octet, char)
  double float_value = 0.0;         ///< kFloat
  std::string string_value;         ///< kString
  std::vector<std::uint8_t> bytes;  ///< kBytes
  std::vector<Value> items;         ///< kList elements, or kStruct fields in declaration order
  std::vector<std::string> names;   ///< kStruct: field names, parallel to `items`
  std::string type_name;            ///< kStruct: DDS type name

  /// Field of a struct by name; throws std::out_of_range naming the field and type.
  const Value& at(std::string_view field_name) const;
  /// Element of a list; throws std::out_of_range.
  const Value& at(std::size_t index) const;
  /// Any integer or float scalar as double (for tests and plotting); throws otherwise.
  double as_double() const;
};

/// Decodes `serialized` (4-byte encapsulation header first: CDR_BE 00 00 or CDR_LE 00 01,
/// i.e. XCDR1; alignment measured from after the header) as `dds_name`. Throws CdrError on
/// malformed, truncated or XCDR2 input, std::out_of_range for an unknown type. Never reads
/// out of bounds; a sequence length is checked against the bytes left before allocating.
Value decode_cdr(const TypeDatabase& database, std::string_view dds_name,
                 std::span<const std::uint8_t> serialized);

struct YamlOptions {
  /// Lists longer than this print their first `max_list_elements` and "... (N more)";
  /// byte sequences longer than this print as "<N bytes>". 0 = print everything.
  std::size_t max_list_elements = 16;
  /// Strings longer than this are cut and end in "..." (ros2 topic echo's truncate length).
  std::size_t max_string_length = 128;
  /// sensor_msgs Image and PointCloud2 `data` always print as "<N bytes>".
  bool summarize_image_data = true;
};

/// YAML text (block style, two-space indents, like `ros2 topic echo`), ending in '\n'.
std::string to_yaml(const Value& value, const YamlOptions& options = {});

}  // namespace avs::introspection
