// XCDR1 encoding driven by a TypeDatabase: the same layout cdr_reader.cpp decodes (every
// primitive aligned to its size from the end of the header, strings with their NUL, sequences
// with a uint32 count first).
#include "avs/introspection/cdr_writer.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace avs::introspection {

namespace {

class CdrEncoder {
 public:
  explicit CdrEncoder(const TypeDatabase& database) : database_(database) {}

  std::vector<std::uint8_t> encode(std::string_view dds_name, const YAML::Node& yaml) {
    const StructType& type = database_.at(dds_name);
    out_ = {0x00, 0x01, 0x00, 0x00};  // CDR_LE
    write_struct(type, yaml, "");
    if (type.fields.empty()) out_.push_back(0);  // an empty message is one byte
    return std::move(out_);
  }

 private:
  [[noreturn]] static void fail(const std::string& path, const std::string& message) {
    throw EncodeError((path.empty() ? "" : path + ": ") + message);
  }

  static std::string got(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + node.Scalar() + "'";
    if (node.IsSequence()) return "a list";
    if (node.IsMap()) return "a mapping";
    return "nothing";
  }

  void align(std::size_t size) {
    while ((out_.size() - 4) % size != 0) out_.push_back(0);
  }

  void put(const void* bytes, std::size_t size) {
    align(size);
    const auto* p = static_cast<const std::uint8_t*>(bytes);
    out_.insert(out_.end(), p, p + size);  // little endian: this machine's order (x86, arm)
  }

  void put_length(std::size_t n) {
    const auto v = static_cast<std::uint32_t>(n);
    put(&v, 4);
  }

  template <class T>
  static bool parse(const std::string& text, T& v) {
    std::string_view s = text;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if constexpr (std::is_floating_point_v<T>) {
      if (s == ".inf" || s == "inf") return v = std::numeric_limits<T>::infinity(), true;
      if (s == "-.inf" || s == "-inf") return v = -std::numeric_limits<T>::infinity(), true;
      if (s == ".nan" || s == "nan") return v = std::numeric_limits<T>::quiet_NaN(), true;
    }
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && ec == std::errc() && end == s.data() + s.size();
  }

  template <class T>
  void put_integer(const YAML::Node& node, const std::string& path) {
    const std::string text = node.IsScalar() ? node.Scalar() : "";
    T v{};
    if (!node.IsScalar() || !parse(text, v)) {
      fail(path,
           "expected an integer in [" +
               std::to_string(static_cast<long long>(std::numeric_limits<T>::min())) + ", " +
               std::to_string(static_cast<unsigned long long>(std::numeric_limits<T>::max())) +
               "], got " + got(node));
    }
    put(&v, sizeof v);
  }

  template <class T>
  void put_float(const YAML::Node& node, const std::string& path) {
    T v{};
    if (!node.IsScalar() || !parse(node.Scalar(), v))
      fail(path, "expected a number, got " + got(node));
    put(&v, sizeof v);
  }

  void write_primitive(Primitive p, const YAML::Node& node, const std::string& path) {
    if (!node.IsDefined() || node.IsNull()) {  // left out: zero
      const std::uint64_t zero = 0;
      put(&zero, primitive_size(p));
      return;
    }
    switch (p) {
      case Primitive::kBool: {
        const std::string text = node.IsScalar() ? node.Scalar() : "";
        if (text != "true" && text != "false")
          fail(path, "expected true or false, got " + got(node));
        const std::uint8_t b = text == "true" ? 1 : 0;
        put(&b, 1);
        return;
      }
      case Primitive::kInt8:
        return put_integer<std::int8_t>(node, path);
      case Primitive::kInt16:
        return put_integer<std::int16_t>(node, path);
      case Primitive::kInt32:
        return put_integer<std::int32_t>(node, path);
      case Primitive::kInt64:
        return put_integer<std::int64_t>(node, path);
      case Primitive::kOctet:
      case Primitive::kChar:
      case Primitive::kUint8:
        return put_integer<std::uint8_t>(node, path);
      case Primitive::kUint16:
        return put_integer<std::uint16_t>(node, path);
      case Primitive::kUint32:
        return put_integer<std::uint32_t>(node, path);
      case Primitive::kUint64:
        return put_integer<std::uint64_t>(node, path);
      case Primitive::kFloat32:
        return put_float<float>(node, path);
      case Primitive::kFloat64:
        return put_float<double>(node, path);
    }
  }

  void write_string(const Field& field, const YAML::Node& node, const std::string& path) {
    std::string text;
    if (node.IsDefined() && !node.IsNull()) {
      if (!node.IsScalar()) fail(path, "expected a string, got " + got(node));
      text = node.Scalar();
    }
    if (field.string_bound && text.size() > *field.string_bound) {
      fail(path, "string of " + std::to_string(text.size()) + " characters, at most " +
                     std::to_string(*field.string_bound));
    }
    put_length(text.size() + 1);
    out_.insert(out_.end(), text.begin(), text.end());
    out_.push_back(0);
  }

  void write_element(const Field& field, const YAML::Node& node, const std::string& path) {
    if (field.kind == FieldKind::kString) return write_string(field, node, path);
    if (field.kind == FieldKind::kPrimitive) return write_primitive(field.primitive, node, path);
    write_struct(database_.at(field.struct_name), node, path);
  }

  void write_collection(const Field& field, const YAML::Node& node, const std::string& path) {
    const bool given = node.IsDefined() && !node.IsNull();
    if (given && !node.IsSequence()) fail(path, "expected a list, got " + got(node));
    const std::size_t count = given ? node.size() : 0;
    if (field.array_length) {
      if (given && count != *field.array_length) {
        fail(path, "expected a list of " + std::to_string(*field.array_length) + ", got " +
                       std::to_string(count));
      }
      for (std::uint32_t i = 0; i < *field.array_length; ++i) {
        write_element(field, given ? node[i] : YAML::Node(), path + "[" + std::to_string(i) + "]");
      }
      return;
    }
    if (field.sequence_bound && count > *field.sequence_bound) {
      fail(path, "list of " + std::to_string(count) + ", at most " +
                     std::to_string(*field.sequence_bound));
    }
    put_length(count);
    for (std::size_t i = 0; i < count; ++i) {
      write_element(field, node[i], path + "[" + std::to_string(i) + "]");
    }
  }

  void write_struct(const StructType& type, const YAML::Node& node, const std::string& path) {
    const bool given = node.IsDefined() && !node.IsNull();
    if (given && !node.IsMap()) {
      fail(path, "expected a mapping of the fields of " + ros_type_name(type.dds_name) + ", got " +
                     got(node));
    }
    if (given) {
      for (const auto& entry : node) {
        const std::string key = entry.first.as<std::string>();
        bool known = false;
        for (const auto& field : type.fields) known = known || field.name == key;
        if (known) continue;
        std::string fields;
        for (const auto& field : type.fields) fields += (fields.empty() ? "" : ", ") + field.name;
        fail(path, "'" + key + "' is not a field of " + ros_type_name(type.dds_name) +
                       " (fields: " + fields + ")");
      }
    }
    for (const auto& field : type.fields) {
      const std::string field_path = path.empty() ? field.name : path + "." + field.name;
      const YAML::Node value = given ? node[field.name] : YAML::Node();
      if (field.is_sequence || field.array_length) {
        write_collection(field, value, field_path);
      } else {
        write_element(field, value, field_path);
      }
    }
  }

  const TypeDatabase& database_;
  std::vector<std::uint8_t> out_;
};

}  // namespace

std::vector<std::uint8_t> encode_cdr(const TypeDatabase& database, std::string_view dds_name,
                                     const YAML::Node& yaml) {
  return CdrEncoder(database).encode(dds_name, yaml);
}

}  // namespace avs::introspection
