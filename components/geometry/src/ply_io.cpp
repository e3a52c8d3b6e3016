// PLY reader (ASCII and binary little-endian) and binary writer.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "avs/geometry/mesh.hpp"
#include "mesh_io_detail.hpp"

namespace avs::geometry {
namespace {

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool parse_scalar(const std::string& name, Scalar& out) {
  static const struct {
    const char* name;
    Scalar type;
  } kTable[] = {
      {"char", Scalar::kInt8},      {"int8", Scalar::kInt8},       {"uchar", Scalar::kUint8},
      {"uint8", Scalar::kUint8},    {"short", Scalar::kInt16},     {"int16", Scalar::kInt16},
      {"ushort", Scalar::kUint16},  {"uint16", Scalar::kUint16},   {"int", Scalar::kInt32},
      {"int32", Scalar::kInt32},    {"uint", Scalar::kUint32},     {"uint32", Scalar::kUint32},
      {"float", Scalar::kFloat32},  {"float32", Scalar::kFloat32}, {"double", Scalar::kFloat64},
      {"float64", Scalar::kFloat64}};
  for (const auto& entry : kTable) {
    if (name == entry.name) {
      out = entry.type;
      return true;
    }
  }
  return false;
}

std::size_t scalar_size(Scalar s) {
  switch (s) {
    case Scalar::kInt8:
    case Scalar::kUint8:
      return 1;
    case Scalar::kInt16:
    case Scalar::kUint16:
      return 2;
    case Scalar::kInt32:
    case Scalar::kUint32:
    case Scalar::kFloat32:
      return 4;
    case Scalar::kFloat64:
      return 8;
  }
  return 0;
}

template <typename T>
T read_raw(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

double decode_scalar(Scalar s, const char* p) {
  switch (s) {
    case Scalar::kInt8:
      return read_raw<std::int8_t>(p);
    case Scalar::kUint8:
      return read_raw<std::uint8_t>(p);
    case Scalar::kInt16:
      return read_raw<std::int16_t>(p);
    case Scalar::kUint16:
      return read_raw<std::uint16_t>(p);
    case Scalar::kInt32:
      return read_raw<std::int32_t>(p);
    case Scalar::kUint32:
      return read_raw<std::uint32_t>(p);
    case Scalar::kFloat32:
      return read_raw<float>(p);
    case Scalar::kFloat64:
      return read_raw<double>(p);
  }
  return 0;
}

struct Property {
  std::string name;
  Scalar type = Scalar::kFloat32;
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  bool binary = false;
  std::vector<Element> elements;
  std::size_t lines = 0;  ///< header lines, so ASCII body line numbers can be reported
};

Header read_header(std::istream& in, const std::string& path) {
  Header header;
  std::string line;
  bool format_seen = false;
  while (std::getline(in, line)) {
    ++header.lines;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (header.lines == 1) {
      if (keyword != "ply") detail::fail(path, 1, "not a PLY file (first line is not 'ply')");
      continue;
    }
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format == "ascii") {
        header.binary = false;
      } else if (format == "binary_little_endian") {
        header.binary = true;
      } else {
        detail::fail(path, header.lines, "unsupported PLY format '" + format + "'");
      }
      format_seen = true;
    } else if (keyword == "element") {
      Element element;
      long long count = -1;
      words >> element.name >> count;
      if (!words || count < 0) detail::fail(path, header.lines, "malformed element line");
      element.count = static_cast<std::size_t>(count);
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) detail::fail(path, header.lines, "property before any element");
      Property property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> property.name;
        property.is_list = true;
        if (!parse_scalar(count_type, property.count_type) ||
            !parse_scalar(item_type, property.type)) {
          detail::fail(path, header.lines, "unknown list type in '" + line + "'");
        }
      } else {
        words >> property.name;
        if (!parse_scalar(type, property.type)) {
          detail::fail(path, header.lines, "unknown property type '" + type + "'");
        }
      }
      if (property.name.empty()) detail::fail(path, header.lines, "property without a name");
      header.elements.back().properties.push_back(property);
    } else if (keyword == "end_header") {
      if (!format_seen) detail::fail(path, header.lines, "end_header before any format line");
      return header;
    } else if (keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      detail::fail(path, header.lines, "unexpected header keyword '" + keyword + "'");
    }
  }
  detail::fail(path, header.lines, "file ends inside the header (no end_header)");
}

/// `value` (a list length or a vertex index, stored in any PLY type) as a whole number in
/// [min, max]; anything else (2.96e29 as a length, found by tests/fuzz) is an error, not a cast
/// out of range.
long long whole_number(double value, double min, double max, const std::string& path,
                       std::size_t line, const std::string& what) {
  if (!(value >= min && value <= max) || value != std::floor(value)) {
    std::ostringstream text;
    text << what << " " << value << " is not a whole number in [" << min << ", " << max << "]";
    detail::fail(path, line, text.str());
  }
  return static_cast<long long>(value);
}

/// A list length and a vertex index as whole_number() accepts them.
long long list_length(double value, const std::string& path, std::size_t line) {
  return whole_number(value, 0, std::numeric_limits<int>::max(), path, line, "list length");
}
int vertex_index(double value, const std::string& path, std::size_t line) {
  return static_cast<int>(whole_number(value, std::numeric_limits<int>::min(),
                                       std::numeric_limits<int>::max(), path, line, "list item"));
}

/// Collects one element item's values; list values go to `list`.
struct ItemSink {
  std::vector<double> scalars;  ///< one per non-list property, in order
  std::vector<int> list;        ///< the (last) list property's items
};

/// Where the scalar property `name` is in an item's `scalars` (which leave the list properties
/// out: a vertex with a list property before x read past them, found by tests/fuzz), or -1.
int index_of(const Element& e, const char* name) {
  int scalar = 0;
  for (const Property& property : e.properties) {
    if (property.is_list) continue;
    if (property.name == name) return scalar;
    ++scalar;
  }
  return -1;
}

void add_item(const Element& element, const ItemSink& item, Mesh& mesh, const std::string& path,
              std::size_t line) {
  if (element.name == "vertex") {
    const int ix = index_of(element, "x"), iy = index_of(element, "y"), iz = index_of(element, "z");
    if (ix < 0 || iy < 0 || iz < 0) detail::fail(path, line, "vertex element lacks x, y or z");
    mesh.vertices.emplace_back(static_cast<float>(item.scalars[ix]),
                               static_cast<float>(item.scalars[iy]),
                               static_cast<float>(item.scalars[iz]));
  } else if (element.name == "face") {
    if (item.list.size() < 3) {
      detail::fail(path, line, "face with " + std::to_string(item.list.size()) + " vertices");
    }
    for (std::size_t k = 1; k + 1 < item.list.size(); ++k) {  // triangle fan
      mesh.triangles.emplace_back(item.list[0], item.list[k], item.list[k + 1]);
    }
  }
}

void read_ascii_body(std::istream& in, const Header& header, Mesh& mesh, const std::string& path) {
  std::size_t line_number = header.lines;
  std::string line;
  for (const Element& element : header.elements) {
    for (std::size_t n = 0; n < element.count; ++n) {
      do {
        if (!std::getline(in, line)) {
          detail::fail(path, line_number, "file ends inside element '" + element.name + "'");
        }
        ++line_number;
      } while (line.find_first_not_of(" \t\r") == std::string::npos);
      std::istringstream words(line);
      ItemSink item;
      for (const Property& property : element.properties) {
        double value = 0;
        if (!(words >> value)) detail::fail(path, line_number, "expected a number");
        if (!property.is_list) {
          item.scalars.push_back(value);
          continue;
        }
        const long long count = list_length(value, path, line_number);
        item.list.clear();
        for (long long k = 0; k < count; ++k) {
          if (!(words >> value)) detail::fail(path, line_number, "list shorter than its length");
          item.list.push_back(vertex_index(value, path, line_number));
        }
      }
      add_item(element, item, mesh, path, line_number);
    }
  }
}

void read_binary_body(std::istream& in, const Header& header, Mesh& mesh, const std::string& path) {
  const std::vector<char> body((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
  std::size_t offset = 0;
  auto need = [&](std::size_t bytes, const Element& element) {
    if (offset + bytes > body.size()) {
      detail::fail(path, 0,
                   "binary body ends inside element '" + element.name + "' (byte " +
                       std::to_string(offset) + " of " + std::to_string(body.size()) + ")");
    }
  };
  for (const Element& element : header.elements) {
    for (std::size_t n = 0; n < element.count; ++n) {
      ItemSink item;
      for (const Property& property : element.properties) {
        if (!property.is_list) {
          need(scalar_size(property.type), element);
          item.scalars.push_back(decode_scalar(property.type, body.data() + offset));
          offset += scalar_size(property.type);
          continue;
        }
        need(scalar_size(property.count_type), element);
        const long long count =
            list_length(decode_scalar(property.count_type, body.data() + offset), path, 0);
        offset += scalar_size(property.count_type);
        need(static_cast<std::size_t>(count) * scalar_size(property.type), element);
        item.list.clear();
        for (long long k = 0; k < count; ++k) {
          item.list.push_back(
              vertex_index(decode_scalar(property.type, body.data() + offset), path, 0));
          offset += scalar_size(property.type);
        }
      }
      add_item(element, item, mesh, path, 0);
    }
  }
}

}  // namespace

namespace detail {

Mesh load_ply(const std::string& path) {
  std::ifstream in = open_input(path);
  const Header header = read_header(in, path);
  Mesh mesh;
  if (header.binary) {
    read_binary_body(in, header, mesh, path);
  } else {
    read_ascii_body(in, header, mesh, path);
  }
  return mesh;
}

}  // namespace detail

void save_ply(const Mesh& mesh, const std::string& path) {
  std::ofstream out = detail::open_output(path);
  out << "ply\nformat binary_little_endian 1.0\ncomment avs mesh, metres\n"
      << "element vertex " << mesh.vertices.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "element face " << mesh.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
  static_assert(std::endian::native == std::endian::little,
                "save_ply assumes a little-endian host");
  for (const Eigen::Vector3f& v : mesh.vertices) {
    out.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(float));
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const std::uint8_t three = 3;
    const std::int32_t idx[3] = {t[0], t[1], t[2]};
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(idx), sizeof(idx));
  }
  if (!out) detail::fail(path, 0, "write failed");
}

}  // namespace avs::geometry
