#include "avs/decode/calibration_yaml.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>
#include <Eigen/LU>

#include "avs/runtime/yaml_checks.hpp"

namespace avs::decode {
namespace {

[[noreturn]] void fail(const std::string& source, const YAML::Node& node, const std::string& what) {
  runtime::yaml_fail(source, node, what);
}

void check_keys(const std::string& source, const YAML::Node& node,
                const std::set<std::string>& allowed, const std::string& section) {
  runtime::yaml_check_keys(source, node, allowed, section);
}

template <typename T>
void read(const std::string& source, const YAML::Node& map, const char* key, T& value) {
  const YAML::Node node = map[key];
  if (!node) return;
  try {
    value = node.as<T>();
  } catch (const YAML::Exception&) {
    fail(source, node, std::string("'") + key + "' has the wrong type");
  }
}

std::vector<double> read_list(const std::string& source, const YAML::Node& node, std::size_t size,
                              const char* key) {
  return runtime::yaml_numbers(source, node, size, key);
}

void read_lens(const std::string& source, const YAML::Node& node, const std::string& section,
               geometry::CameraModel& lens) {
  check_keys(source, node, {"width", "height", "fx", "fy", "cx", "cy", "distortion"}, section);
  read(source, node, "width", lens.width);
  read(source, node, "height", lens.height);
  read(source, node, "fx", lens.fx_px);
  read(source, node, "fy", lens.fy_px);
  read(source, node, "cx", lens.cx_px);
  read(source, node, "cy", lens.cy_px);
  if (const YAML::Node d_node = node["distortion"]) {
    // 5 (k1 k2 p1 p2 k3, plumb_bob) or 8 (and k4 k5 k6, rational_polynomial), OpenCV order.
    const std::size_t count = d_node.IsSequence() && d_node.size() == 8 ? 8 : 5;
    const auto d = read_list(source, d_node, count, "distortion");
    lens.set_distortion_coefficients(d);
  }
  if (const std::string why = lens.problem(); !why.empty()) {
    fail(source, node, section + ": " + why);
  }
}

void write_lens(YAML::Emitter& out, const char* name, const geometry::CameraModel& lens) {
  out << YAML::Key << name << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "width" << YAML::Value << lens.width << YAML::Key << "height" << YAML::Value
      << lens.height;
  out << YAML::Key << "fx" << YAML::Value << lens.fx_px << YAML::Key << "fy" << YAML::Value
      << lens.fy_px;
  out << YAML::Key << "cx" << YAML::Value << lens.cx_px << YAML::Key << "cy" << YAML::Value
      << lens.cy_px;
  out << YAML::Key << "distortion" << YAML::Value << YAML::Flow << lens.distortion_coefficients();
  out << YAML::EndMap;
}

SensorGeometry parse_root(const std::string& text, const std::string& source) {
  const YAML::Node root = runtime::yaml_parse(text, source);
  SensorGeometry g = default_sensor_geometry();
  if (!root || root.IsNull()) return g;
  check_keys(source, root,
             {"camera", "projector", "R_projector_camera", "t_projector_camera_m", "code_layout"},
             "calibration");
  if (root["camera"]) read_lens(source, root["camera"], "camera", g.camera);
  if (root["projector"]) read_lens(source, root["projector"], "projector", g.projector);
  if (root["R_projector_camera"]) {
    const auto r = read_list(source, root["R_projector_camera"], 9, "R_projector_camera");
    for (int i = 0; i < 9; ++i) g.R_projector_camera(i / 3, i % 3) = r[i];
    const double orthogonality =
        (g.R_projector_camera * g.R_projector_camera.transpose() - Eigen::Matrix3d::Identity())
            .norm();
    if (orthogonality > 1e-6 || g.R_projector_camera.determinant() < 0) {
      fail(source, root["R_projector_camera"], "R_projector_camera is not a rotation");
    }
  }
  if (root["t_projector_camera_m"]) {
    const auto t = read_list(source, root["t_projector_camera_m"], 3, "t_projector_camera_m");
    g.t_projector_camera_m = {t[0], t[1], t[2]};
  }
  if (const YAML::Node layout = root["code_layout"]) {
    check_keys(source, layout, {"bit_count", "code_count", "rows_per_code", "first_row"},
               "code_layout");
    read(source, layout, "bit_count", g.layout.bit_count);
    read(source, layout, "code_count", g.layout.code_count);
    read(source, layout, "rows_per_code", g.layout.rows_per_code);
    read(source, layout, "first_row", g.layout.first_row);
    if (g.layout.bit_count < 1 || g.layout.bit_count > 15 || g.layout.code_count < 1 ||
        g.layout.code_count > (1 << g.layout.bit_count) || g.layout.rows_per_code < 1) {
      fail(source, layout, "code_layout: need 1..15 bits, 1..2^bits codes, rows_per_code >= 1");
    }
  }
  return g;
}

}  // namespace

SensorGeometry parse_sensor_geometry_yaml(const std::string& text, const std::string& source) {
  try {
    return parse_root(text, source);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(runtime::yaml_error_message(source, e));
  }
}

SensorGeometry load_sensor_geometry_yaml(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open calibration file");
  std::stringstream text;
  text << file.rdbuf();
  return parse_sensor_geometry_yaml(text.str(), path);
}

std::string sensor_geometry_to_yaml(const SensorGeometry& g) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  write_lens(out, "camera", g.camera);
  write_lens(out, "projector", g.projector);
  std::vector<double> r(9),
      t{g.t_projector_camera_m.x(), g.t_projector_camera_m.y(), g.t_projector_camera_m.z()};
  for (int i = 0; i < 9; ++i) r[i] = g.R_projector_camera(i / 3, i % 3);
  out << YAML::Key << "R_projector_camera" << YAML::Value << YAML::Flow << r;
  out << YAML::Key << "t_projector_camera_m" << YAML::Value << YAML::Flow << t;
  out << YAML::Key << "code_layout" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "bit_count" << YAML::Value << g.layout.bit_count;
  out << YAML::Key << "code_count" << YAML::Value << g.layout.code_count;
  out << YAML::Key << "rows_per_code" << YAML::Value << g.layout.rows_per_code;
  out << YAML::Key << "first_row" << YAML::Value << g.layout.first_row;
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace avs::decode
