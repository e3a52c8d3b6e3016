// XCDR1 (classic CDR) decoding driven by a TypeDatabase. Every read is bounds-checked; an
// error names the absolute byte offset and the field path being decoded.
#include "avs/introspection/cdr_reader.hpp"

#include <bit>
#include <cstring>
#include <string>

namespace avs::introspection {

namespace {

constexpr std::size_t kHeaderSize = 4;

class CdrDecoder {
 public:
  CdrDecoder(const TypeDatabase& database, std::span<const std::uint8_t> serialized)
      : database_(database), data_(serialized) {}

  Value decode(std::string_view dds_name) {
    const auto& type = database_.at(dds_name);
    path_ = type.dds_name;
    read_header();
    return read_struct(type);
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw CdrError(
        "CDR: " + message + " at byte " + std::to_string(kHeaderSize + pos_) + " reading " + path_,
        kHeaderSize + pos_);
  }

  void read_header() {
    if (data_.size() < kHeaderSize) {
      throw CdrError("CDR: " + std::to_string(data_.size()) +
                         " bytes, shorter than the 4-byte encapsulation header",
                     0);
    }
    const unsigned id = (unsigned{data_[0]} << 8) | data_[1];
    if (id != 0x0000 && id != 0x0001) {
      const bool xcdr2 = id >= 0x0006 && id <= 0x000b;
      throw CdrError(
          "CDR: encapsulation 0x" + std::string(id < 0x10 ? "000" : "") + to_hex(id) +
              (xcdr2 ? " is XCDR2, which is not supported (ROS 2 uses XCDR1: 0x0000/0x0001)"
                     : " is not CDR_BE (0x0000) or CDR_LE (0x0001)"),
          0);
    }
    swap_ = (id == 0x0001) != (std::endian::native == std::endian::little);
    body_ = data_.subspan(kHeaderSize);
  }

  static std::string to_hex(unsigned value) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    do {
      out.insert(out.begin(), digits[value & 0xf]);
      value >>= 4;
    } while (value);
    return out;
  }

  std::size_t remaining() const { return body_.size() - pos_; }

  void need(std::size_t bytes, const char* what) {
    if (bytes > remaining()) {
      fail("truncated: " + std::string(what) + " needs " + std::to_string(bytes) + " bytes, " +
           std::to_string(remaining()) + " left");
    }
  }

  // XCDR1: every primitive is aligned to its size, counted from the end of the header.
  void align(std::size_t alignment) {
    const auto padding = (alignment - pos_ % alignment) % alignment;
    need(padding, "alignment padding");
    pos_ += padding;
  }

  std::uint64_t read_raw(std::size_t size) {
    align(size);
    need(size, "value");
    std::uint8_t bytes[8];
    std::memcpy(bytes, body_.data() + pos_, size);
    if (swap_) {
      for (std::size_t i = 0; i < size / 2; ++i) std::swap(bytes[i], bytes[size - 1 - i]);
    }
    pos_ += size;
    std::uint64_t out = 0;
    switch (size) {
      case 1:
        out = bytes[0];
        break;
      case 2: {
        std::uint16_t v;
        std::memcpy(&v, bytes, 2);
        out = v;
        break;
      }
      case 4: {
        std::uint32_t v;
        std::memcpy(&v, bytes, 4);
        out = v;
        break;
      }
      default:
        std::memcpy(&out, bytes, 8);
        break;
    }
    return out;
  }

  std::uint32_t read_length() { return static_cast<std::uint32_t>(read_raw(4)); }

  Value read_primitive(Primitive primitive) {
    Value value;
    value.primitive = primitive;
    const auto raw = read_raw(primitive_size(primitive));
    switch (primitive) {
      case Primitive::kBool:
        if (raw > 1) {
          pos_ -= 1;
          fail("boolean byte " + std::to_string(raw) + " is neither 0 nor 1");
        }
        value.kind = Value::Kind::kBool;
        value.bool_value = raw != 0;
        break;
      case Primitive::kInt8:
        value.kind = Value::Kind::kInt;
        value.int_value = static_cast<std::int8_t>(raw);
        break;
      case Primitive::kInt16:
        value.kind = Value::Kind::kInt;
        value.int_value = static_cast<std::int16_t>(raw);
        break;
      case Primitive::kInt32:
        value.kind = Value::Kind::kInt;
        value.int_value = static_cast<std::int32_t>(raw);
        break;
      case Primitive::kInt64:
        value.kind = Value::Kind::kInt;
        value.int_value = static_cast<std::int64_t>(raw);
        break;
      case Primitive::kFloat32:
        value.kind = Value::Kind::kFloat;
        value.float_value = std::bit_cast<float>(static_cast<std::uint32_t>(raw));
        break;
      case Primitive::kFloat64:
        value.kind = Value::Kind::kFloat;
        value.float_value = std::bit_cast<double>(raw);
        break;
      default:
        value.kind = Value::Kind::kUint;
        value.uint_value = raw;
        break;
    }
    return value;
  }

  Value read_string() {
    const auto length = read_length();  // includes the terminating NUL
    Value value;
    value.kind = Value::Kind::kString;
    if (length == 0) return value;  // tolerated: some writers send 0 for ""
    need(length, "string");
    if (body_[pos_ + length - 1] != 0) {
      pos_ += length - 1;
      fail("string of length " + std::to_string(length) + " does not end in NUL");
    }
    value.string_value.assign(reinterpret_cast<const char*>(body_.data() + pos_), length - 1);
    pos_ += length;
    return value;
  }

  Value read_element(const Field& field) {
    if (field.kind == FieldKind::kString) return read_string();
    if (field.kind == FieldKind::kPrimitive) return read_primitive(field.primitive);
    return read_struct(database_.at(field.struct_name));
  }

  // A sequence (count first) or a fixed array of `field`'s element type.
  Value read_collection(const Field& field) {
    const std::uint32_t count = field.is_sequence ? read_length() : *field.array_length;
    if (field.is_sequence && field.sequence_bound && count > *field.sequence_bound) {
      pos_ -= 4;
      fail("sequence of " + std::to_string(count) + " exceeds its bound " +
           std::to_string(*field.sequence_bound));
    }
    Value list;
    const bool is_bytes =
        field.kind == FieldKind::kPrimitive &&
        (field.primitive == Primitive::kUint8 || field.primitive == Primitive::kOctet);
    if (is_bytes) {
      need(count, "byte sequence");
      list.kind = Value::Kind::kBytes;
      list.primitive = field.primitive;
      list.bytes.assign(body_.begin() + static_cast<std::ptrdiff_t>(pos_),
                        body_.begin() + static_cast<std::ptrdiff_t>(pos_ + count));
      pos_ += count;
      return list;
    }
    list.kind = Value::Kind::kList;
    // Check the minimum size before reserving, so a corrupt count cannot allocate gigabytes.
    if (field.kind == FieldKind::kPrimitive && count > 0) {
      const auto size = primitive_size(field.primitive);
      align(size);
      need(std::size_t{count} * size, "sequence elements");
      list.items.reserve(count);
    }
    for (std::uint32_t i = 0; i < count; ++i) {
      if (remaining() == 0)
        fail("truncated: element " + std::to_string(i) + " of " + std::to_string(count));
      list.items.push_back(read_element(field));
    }
    return list;
  }

  Value read_struct(const StructType& type) {
    Value value;
    value.kind = Value::Kind::kStruct;
    value.type_name = type.dds_name;
    value.items.reserve(type.fields.size());
    value.names.reserve(type.fields.size());
    const auto path_length = path_.size();
    for (const auto& field : type.fields) {
      path_.resize(path_length);
      path_ += "." + field.name;
      value.names.push_back(field.name);
      value.items.push_back(field.is_sequence || field.array_length ? read_collection(field)
                                                                    : read_element(field));
    }
    path_.resize(path_length);
    return value;
  }

  const TypeDatabase& database_;
  std::span<const std::uint8_t> data_;
  std::span<const std::uint8_t> body_;
  std::size_t pos_ = 0;  // within body_ (alignment origin)
  bool swap_ = false;
  std::string path_;  // "type.field.field" being decoded, for error messages
};

}  // namespace

Value decode_cdr(const TypeDatabase& database, std::string_view dds_name,
                 std::span<const std::uint8_t> serialized) {
  return CdrDecoder(database, serialized).decode(dds_name);
}

const Value& Value::at(std::string_view field_name) const {
  for (std::size_t i = 0; kind == Kind::kStruct && i < names.size(); ++i) {
    if (names[i] == field_name) return items[i];
  }
  throw std::out_of_range("no field '" + std::string(field_name) + "' in " +
                          (kind == Kind::kStruct ? type_name : std::string("a non-struct value")));
}

const Value& Value::at(std::size_t index) const {
  if (kind != Kind::kList || index >= items.size()) {
    throw std::out_of_range("list index " + std::to_string(index) + " out of range (size " +
                            std::to_string(kind == Kind::kList ? items.size() : 0) + ")");
  }
  return items[index];
}

double Value::as_double() const {
  switch (kind) {
    case Kind::kInt:
      return static_cast<double>(int_value);
    case Kind::kUint:
      return static_cast<double>(uint_value);
    case Kind::kFloat:
      return float_value;
    case Kind::kBool:
      return bool_value ? 1.0 : 0.0;
    default:
      throw std::invalid_argument("value is not a number");
  }
}

}  // namespace avs::introspection
