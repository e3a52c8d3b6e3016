// Type introspection for avs topics: a database of every struct in our IDL (parsed from the
// IDL text itself), and the ROS 2 names and `.msg` definitions derived from it.
// See docs/introspection.md for the supported IDL subset.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace avs::introspection {

/// An IDL file that cannot be parsed; what() starts with "file:line: ".
class IdlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Scalar IDL types (strings are separate: FieldKind::kString).
enum class Primitive : std::uint8_t {
  kBool,
  kOctet,
  kChar,
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64,
};

/// Size in bytes in CDR (also its XCDR1 alignment).
std::size_t primitive_size(Primitive primitive);
/// ROS 2 `.msg` spelling: "bool", "byte", "char", "uint8", ..., "float32", "float64".
std::string_view ros_primitive_name(Primitive primitive);

enum class FieldKind : std::uint8_t { kPrimitive, kString, kStruct };

/// One struct member, in declaration order.
struct Field {
  std::string name;
  FieldKind kind = FieldKind::kPrimitive;
  Primitive primitive = Primitive::kUint8;      ///< element type when kind == kPrimitive
  std::string struct_name;                      ///< element DDS name when kind == kStruct
  bool is_sequence = false;                     ///< sequence<T> (or sequence<T, bound>)
  std::optional<std::uint32_t> array_length;    ///< `T name[N]`
  std::optional<std::uint32_t> sequence_bound;  ///< sequence<T, N>
  std::optional<std::uint32_t> string_bound;    ///< string<N>
};

/// A constant from the `<Type>_Constants` module next to its struct.
struct Constant {
  std::string name;
  FieldKind kind = FieldKind::kPrimitive;  ///< kPrimitive or kString
  Primitive primitive = Primitive::kUint8;
  std::string value;  ///< the literal as written in the IDL (e.g. "1", "-2.5", "\"abc\"")
};

struct StructType {
  std::string dds_name;  ///< e.g. "sensor_msgs::msg::dds_::Image_"
  std::string file;      ///< IDL file it came from, and the line of `struct`
  int line = 0;
  std::vector<Field> fields;
  std::vector<Constant> constants;
};

/// Every struct of a set of IDL files, by fully qualified DDS name.
class TypeDatabase {
 public:
  /// Parses one IDL file (the restricted subset, see docs/introspection.md) and adds its
  /// structs and constants. Throws IdlError naming `file_name:line`.
  void add_idl(std::string_view file_name, std::string_view text);
  /// Checks that every referenced struct and every `<Type>_Constants` module resolves;
  /// call after the last add_idl(). Throws IdlError naming the referring file and line.
  void resolve();

  const StructType* find(std::string_view dds_name) const;
  /// Throws std::out_of_range naming `dds_name` when unknown.
  const StructType& at(std::string_view dds_name) const;
  const std::map<std::string, StructType, std::less<>>& types() const { return types_; }

 private:
  struct PendingConstants {
    std::string target_dds_name;  ///< "<scope>::<Type>_"
    std::string file;
    int line = 0;
    std::vector<Constant> constants;
  };
  struct PendingReference {
    std::string owner;  ///< struct holding the field
    std::size_t field_index = 0;
    std::vector<std::string> scope;  ///< modules enclosing the owner, for relative names
    int line = 0;
  };
  friend class IdlParser;

  std::map<std::string, StructType, std::less<>> types_;
  std::vector<PendingConstants> pending_constants_;
  std::vector<PendingReference> pending_references_;
};

/// The database of every IDL file compiled into this build (avs::msg::idl_sources()),
/// parsed and resolved once on first use. Throws IdlError if our own IDL is unsupported.
const TypeDatabase& built_in_types();

/// ROS 2 type name for a DDS type name, as rmw_cyclonedds demangles it:
/// "sensor_msgs::msg::dds_::Image_" -> "sensor_msgs/msg/Image". Names without "dds_::" or
/// the trailing '_' are returned unchanged.
std::string ros_type_name(std::string_view dds_name);

/// The inverse, as rmw_cyclonedds mangles ROS names: "sensor_msgs/msg/Image" ->
/// "sensor_msgs::msg::dds_::Image_"; the short form "sensor_msgs/Image" (as `ros2 topic pub`
/// takes it) is a message type. Returns "" for a name that is neither "pkg/ns/Type" nor
/// "pkg/Type".
std::string dds_type_name(std::string_view ros_type_name);

/// The complete `ros2msg` definition as rosbag2 stores it in MCAP Schema records: the root
/// type's `.msg` text (constants first, then fields), then each dependency depth-first, each
/// once, in alphabetical order per definition, as "\n" + 80 '=' + "\nMSG: pkg/Type\n" + text.
/// Types of the root's package are written unqualified (`PointField[] fields`), others as
/// `pkg/Type` (`std_msgs/Header header`), as the ROS 2 `.msg` files do.
std::string ros2msg_definition(const TypeDatabase& database, std::string_view dds_name);

}  // namespace avs::introspection
