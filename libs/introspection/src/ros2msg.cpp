// ROS 2 names and `.msg` text for the types of a TypeDatabase, laid out as rosbag2 stores
// them in MCAP schemas (rosbag2_cpp LocalMessageDefinitionSource::get_full_text).
#include <functional>
#include <set>
#include <string>

#include "avs/introspection/type_database.hpp"
#include "avs/msg/type_registry.hpp"

namespace avs::introspection {

std::size_t primitive_size(Primitive primitive) {
  switch (primitive) {
    case Primitive::kBool:
    case Primitive::kOctet:
    case Primitive::kChar:
    case Primitive::kInt8:
    case Primitive::kUint8:
      return 1;
    case Primitive::kInt16:
    case Primitive::kUint16:
      return 2;
    case Primitive::kInt32:
    case Primitive::kUint32:
    case Primitive::kFloat32:
      return 4;
    case Primitive::kInt64:
    case Primitive::kUint64:
    case Primitive::kFloat64:
      return 8;
  }
  return 1;
}

std::string_view ros_primitive_name(Primitive primitive) {
  switch (primitive) {
    case Primitive::kBool:
      return "bool";
    case Primitive::kOctet:
      return "byte";
    case Primitive::kChar:
      return "char";
    case Primitive::kInt8:
      return "int8";
    case Primitive::kUint8:
      return "uint8";
    case Primitive::kInt16:
      return "int16";
    case Primitive::kUint16:
      return "uint16";
    case Primitive::kInt32:
      return "int32";
    case Primitive::kUint32:
      return "uint32";
    case Primitive::kInt64:
      return "int64";
    case Primitive::kUint64:
      return "uint64";
    case Primitive::kFloat32:
      return "float32";
    case Primitive::kFloat64:
      return "float64";
  }
  return "?";
}

const TypeDatabase& built_in_types() {
  static const TypeDatabase database = [] {
    TypeDatabase db;
    for (const auto& source : avs::msg::idl_sources()) db.add_idl(source.file_name, source.text);
    db.resolve();
    return db;
  }();
  return database;
}

std::string ros_type_name(std::string_view dds_name) {
  const auto marker = dds_name.find("dds_::");
  if (marker == std::string_view::npos || dds_name.empty() || dds_name.back() != '_') {
    return std::string(dds_name);
  }
  std::string out;
  for (const char c : dds_name.substr(0, marker)) {
    if (c != ':') {
      out += c;
    } else if (out.empty() || out.back() != '/') {
      out += '/';
    }
  }
  const auto name = dds_name.substr(marker + 6);
  return out + std::string(name.substr(0, name.size() - 1));
}

std::string dds_type_name(std::string_view ros_name) {
  const auto first = ros_name.find('/');
  const auto last = ros_name.rfind('/');
  if (first != std::string_view::npos && first > 0 && last == first && last + 1 < ros_name.size()) {
    // "std_msgs/Bool": the short form `ros2 topic pub` takes, a message type.
    return std::string(ros_name.substr(0, first)) +
           "::msg::dds_::" + std::string(ros_name.substr(last + 1)) + "_";
  }
  if (first == std::string_view::npos || first == 0 || last == first ||
      last + 1 == ros_name.size() || ros_name.find('/', first + 1) != last) {
    return "";
  }
  return std::string(ros_name.substr(0, first)) +
         "::" + std::string(ros_name.substr(first + 1, last - first - 1)) +
         "::dds_::" + std::string(ros_name.substr(last + 1)) + "_";
}

namespace {

// "sensor_msgs/msg/Image" -> {"sensor_msgs", "Image"}; the `.msg` reference form drops "/msg/".
struct RosName {
  std::string package;
  std::string type;
  std::string qualified() const { return package.empty() ? type : package + "/" + type; }
};

RosName ros_name(std::string_view dds_name) {
  const auto full = ros_type_name(dds_name);
  const auto first = full.find('/');
  const auto last = full.rfind('/');
  if (first == std::string::npos) return {"", full};
  return {full.substr(0, first), full.substr(last + 1)};
}

std::string field_type_text(const TypeDatabase& database, const Field& field,
                            const std::string& package, std::set<std::string>& dependencies) {
  std::string text;
  if (field.kind == FieldKind::kStruct) {
    const auto name = ros_name(database.at(field.struct_name).dds_name);
    dependencies.insert(name.qualified());
    text = name.package == package ? name.type : name.qualified();
  } else if (field.kind == FieldKind::kString) {
    text = "string";
    if (field.string_bound) text += "<=" + std::to_string(*field.string_bound);
  } else {
    text = ros_primitive_name(field.primitive);
  }
  if (field.array_length) text += "[" + std::to_string(*field.array_length) + "]";
  if (field.is_sequence)
    text += field.sequence_bound ? "[<=" + std::to_string(*field.sequence_bound) + "]" : "[]";
  return text;
}

// One `.msg` file: constants first (as the ROS 2 files write them), then fields.
std::string msg_text(const TypeDatabase& database, const StructType& type,
                     std::set<std::string>& dependencies) {
  const auto package = ros_name(type.dds_name).package;
  std::string text;
  for (const auto& constant : type.constants) {
    const auto type_text = constant.kind == FieldKind::kString
                               ? std::string("string")
                               : std::string(ros_primitive_name(constant.primitive));
    text += type_text + " " + constant.name + "=" + constant.value + "\n";
  }
  for (const auto& field : type.fields) {
    text += field_type_text(database, field, package, dependencies) + " " + field.name + "\n";
  }
  return text;
}

}  // namespace

std::string ros2msg_definition(const TypeDatabase& database, std::string_view dds_name) {
  // "pkg/Type" (as rosbag2 names dependencies) -> DDS name.
  std::map<std::string, std::string> dds_by_ros;
  for (const auto& [name, type] : database.types()) dds_by_ros[ros_name(name).qualified()] = name;

  std::set<std::string> seen;
  const std::function<std::string(const StructType&)> append = [&](const StructType& type) {
    std::set<std::string> dependencies;  // alphabetical, like rosbag2's std::set
    std::string text = msg_text(database, type, dependencies);
    for (const auto& dependency : dependencies) {
      if (!seen.insert(dependency).second) continue;
      text += "\n" + std::string(80, '=') + "\nMSG: " + dependency + "\n";
      text += append(database.at(dds_by_ros.at(dependency)));
    }
    return text;
  };
  return append(database.at(dds_name));
}

}  // namespace avs::introspection
