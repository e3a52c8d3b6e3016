#include "avs/calib/capture_folder.hpp"

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "avs/decode/calibration_yaml.hpp"
#include "avs/runtime/yaml_checks.hpp"

namespace avs::calib {
namespace {

constexpr const char* kFormat = "avs-calib-capture-1";

[[noreturn]] void fail(const std::string& source, const YAML::Node& node, const std::string& what) {
  runtime::yaml_fail(source, node, what);
}

YAML::Node required(const std::string& source, const YAML::Node& map, const char* key) {
  const YAML::Node node = map[key];
  if (!node) fail(source, map, std::string("missing key '") + key + "'");
  return node;
}

template <typename T>
T as(const std::string& source, const YAML::Node& node, const char* what) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    fail(source, node, std::string("'") + what + "' has the wrong type");
  }
}

void check_keys(const std::string& source, const YAML::Node& node,
                const std::set<std::string>& allowed, const std::string& section) {
  runtime::yaml_check_keys(source, node, allowed, section);
}

std::vector<double> numbers(const std::string& source, const YAML::Node& node, std::size_t size,
                            const char* what) {
  return runtime::yaml_numbers(source, node, size, what);
}

void write_layout(YAML::Emitter& out, const char* key, const decode::CodeLayout& layout) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "bit_count" << YAML::Value << layout.bit_count;
  out << YAML::Key << "code_count" << YAML::Value << layout.code_count;
  out << YAML::Key << "pixels_per_code" << YAML::Value << layout.rows_per_code;
  out << YAML::Key << "first_pixel" << YAML::Value << layout.first_row;
  out << YAML::EndMap;
}

decode::CodeLayout read_layout(const std::string& source, const YAML::Node& node,
                               const char* section) {
  check_keys(source, node, {"bit_count", "code_count", "pixels_per_code", "first_pixel"}, section);
  decode::CodeLayout layout;
  layout.bit_count = as<int>(source, required(source, node, "bit_count"), "bit_count");
  layout.code_count = as<int>(source, required(source, node, "code_count"), "code_count");
  layout.rows_per_code =
      as<int>(source, required(source, node, "pixels_per_code"), "pixels_per_code");
  layout.first_row = as<int>(source, required(source, node, "first_pixel"), "first_pixel");
  if (layout.bit_count < 1 || layout.bit_count > 15 || layout.code_count < 1 ||
      layout.code_count > (1 << layout.bit_count) || layout.rows_per_code < 1) {
    fail(source, node, std::string(section) + ": need 1..15 bits, 1..2^bits codes, >= 1 pixel");
  }
  return layout;
}

void write_board(YAML::Emitter& out, const sim::Checkerboard& b) {
  out << YAML::Key << "board" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "squares_x" << YAML::Value << b.squares_x;
  out << YAML::Key << "squares_y" << YAML::Value << b.squares_y;
  out << YAML::Key << "square_m" << YAML::Value << b.square_m;
  out << YAML::Key << "margin_m" << YAML::Value << b.margin_m;
  out << YAML::Key << "dark_albedo" << YAML::Value << b.dark_albedo;
  out << YAML::Key << "light_albedo" << YAML::Value << b.light_albedo;
  out << YAML::EndMap;
}

sim::Checkerboard read_board(const std::string& source, const YAML::Node& node) {
  check_keys(source, node,
             {"squares_x", "squares_y", "square_m", "margin_m", "dark_albedo", "light_albedo"},
             "board");
  sim::Checkerboard b;
  const auto read = [&](const char* key, auto& value) {
    if (const YAML::Node n = node[key]) {
      value = as<std::remove_reference_t<decltype(value)>>(source, n, key);
    }
  };
  read("squares_x", b.squares_x);
  read("squares_y", b.squares_y);
  read("square_m", b.square_m);
  read("margin_m", b.margin_m);
  read("dark_albedo", b.dark_albedo);
  read("light_albedo", b.light_albedo);
  if (const std::string why = b.problem(); !why.empty()) fail(source, node, "board: " + why);
  return b;
}

void write_size(YAML::Emitter& out, const char* key, int width, int height) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "width"
      << YAML::Value << width << YAML::Key << "height" << YAML::Value << height << YAML::EndMap;
}

std::pair<int, int> read_size(const std::string& source, const YAML::Node& node,
                              const char* section) {
  check_keys(source, node, {"width", "height"}, section);
  const int w = as<int>(source, required(source, node, "width"), "width");
  const int h = as<int>(source, required(source, node, "height"), "height");
  if (w <= 0 || h <= 0) fail(source, node, std::string(section) + ": sizes must be positive");
  return {w, h};
}

std::string read_text(const std::filesystem::path& path, const char* what) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path.string() + ": cannot open " + what);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace

void write_capture_index(const std::filesystem::path& dir, const CaptureIndex& index) {
  const CaptureInfo& info = index.info;
  std::filesystem::create_directories(dir);
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kFormat;
  out << YAML::Key << "source" << YAML::Value << info.source;
  write_size(out, "camera", info.camera_width, info.camera_height);
  write_size(out, "projector", info.codes.projector_width, info.codes.projector_height);
  write_layout(out, "column_code", info.codes.columns);
  write_layout(out, "row_code", info.codes.rows);
  out << YAML::Key << "depth_code_layout" << YAML::Value << YAML::Flow << YAML::BeginMap
      << YAML::Key << "bit_count" << YAML::Value << info.depth_code_layout.bit_count << YAML::Key
      << "code_count" << YAML::Value << info.depth_code_layout.code_count << YAML::Key
      << "rows_per_code" << YAML::Value << info.depth_code_layout.rows_per_code << YAML::Key
      << "first_row" << YAML::Value << info.depth_code_layout.first_row << YAML::EndMap;
  write_board(out, info.board);
  if (info.truth) {
    out << YAML::Key << "truth_calibration" << YAML::Value << "truth_calibration.yaml";
  }
  out << YAML::Key << "frames" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const FrameId& f : capture_frames(info.codes)) out << f.file_name();
  out << YAML::EndSeq;
  out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (const ViewEntry& v : index.views) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << v.name;
    if (v.T_camera_board_truth) {
      std::vector<double> m;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) m.push_back(v.T_camera_board_truth->matrix()(i, j));
      }
      out << YAML::Key << "T_camera_board_truth" << YAML::Value << YAML::Flow << m;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  std::ofstream file(dir / "index.yaml");
  file << out.c_str() << "\n";
  if (!file) throw std::runtime_error((dir / "index.yaml").string() + ": cannot write");
  if (info.truth) {
    std::ofstream truth(dir / "truth_calibration.yaml");
    truth << decode::sensor_geometry_to_yaml(*info.truth);
    if (!truth)
      throw std::runtime_error((dir / "truth_calibration.yaml").string() + ": cannot write");
  }
}

void write_view_frames(const std::filesystem::path& dir, const BoardView& view,
                       const CaptureInfo& info) {
  const std::vector<FrameId> frames = capture_frames(info.codes);
  if (frames.size() != view.frames.size()) {
    throw std::invalid_argument("calib: view '" + view.name + "' has the wrong frame count");
  }
  std::filesystem::create_directories(dir / view.name);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    decode::write_png_gray8((dir / view.name / frames[f].file_name()).string(), view.frames[f]);
  }
}

CaptureIndex read_capture_index(const std::filesystem::path& dir) {
  const std::string source = (dir / "index.yaml").string();
  const YAML::Node root =
      runtime::yaml_parse(read_text(dir / "index.yaml", "capture index"), source);
  check_keys(source, root,
             {"format", "source", "camera", "projector", "column_code", "row_code",
              "depth_code_layout", "board", "truth_calibration", "frames", "views"},
             "capture index");
  const auto format = as<std::string>(source, required(source, root, "format"), "format");
  if (format != kFormat) {
    fail(source, root["format"], "format '" + format + "', expected '" + kFormat + "'");
  }
  CaptureIndex index;
  CaptureInfo& info = index.info;
  info.source = as<std::string>(source, required(source, root, "source"), "source");
  std::tie(info.camera_width, info.camera_height) =
      read_size(source, required(source, root, "camera"), "camera");
  std::tie(info.codes.projector_width, info.codes.projector_height) =
      read_size(source, required(source, root, "projector"), "projector");
  info.codes.columns = read_layout(source, required(source, root, "column_code"), "column_code");
  info.codes.rows = read_layout(source, required(source, root, "row_code"), "row_code");
  {
    // The rig's depth layout, in the calibration file's own terms (rows_per_code, first_row).
    const YAML::Node d = required(source, root, "depth_code_layout");
    check_keys(source, d, {"bit_count", "code_count", "rows_per_code", "first_row"},
               "depth_code_layout");
    info.depth_code_layout.bit_count =
        as<int>(source, required(source, d, "bit_count"), "bit_count");
    info.depth_code_layout.code_count =
        as<int>(source, required(source, d, "code_count"), "code_count");
    info.depth_code_layout.rows_per_code =
        as<int>(source, required(source, d, "rows_per_code"), "rows_per_code");
    info.depth_code_layout.first_row =
        as<int>(source, required(source, d, "first_row"), "first_row");
  }
  info.board = read_board(source, required(source, root, "board"));
  if (const YAML::Node t = root["truth_calibration"]) {
    info.truth = decode::load_sensor_geometry_yaml(
        (dir / as<std::string>(source, t, "truth_calibration")).string());
  }
  const YAML::Node frames = required(source, root, "frames");
  const std::vector<FrameId> expected = capture_frames(info.codes);
  if (!frames.IsSequence() || frames.size() != expected.size()) {
    fail(source, frames,
         "'frames' must list the " + std::to_string(expected.size()) +
             " frame files of a view for these codes");
  }
  for (std::size_t f = 0; f < expected.size(); ++f) {
    if (as<std::string>(source, frames[f], "frames") != expected[f].file_name()) {
      fail(source, frames[f],
           "frame " + std::to_string(f) + " must be '" + expected[f].file_name() + "'");
    }
  }
  const YAML::Node views = required(source, root, "views");
  if (!views.IsSequence()) fail(source, views, "'views' must be a list");
  for (const YAML::Node& v : views) {
    check_keys(source, v, {"name", "T_camera_board_truth"}, "view");
    ViewEntry entry;
    entry.name = as<std::string>(source, required(source, v, "name"), "name");
    if (const YAML::Node t = v["T_camera_board_truth"]) {
      const std::vector<double> m = numbers(source, t, 12, "T_camera_board_truth");
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      for (int i = 0; i < 12; ++i) T.matrix()(i / 4, i % 4) = m[static_cast<std::size_t>(i)];
      entry.T_camera_board_truth = T;
    }
    index.views.push_back(entry);
  }
  return index;
}

BoardView read_view(const std::filesystem::path& dir, const ViewEntry& entry,
                    const CaptureInfo& info) {
  BoardView view;
  view.name = entry.name;
  view.T_camera_board_truth = entry.T_camera_board_truth;
  for (const FrameId& f : capture_frames(info.codes)) {
    const std::filesystem::path path = dir / entry.name / f.file_name();
    decode::GrayImage8 image = decode::read_png_gray8(path.string());
    if (image.width != info.camera_width || image.height != info.camera_height) {
      throw std::runtime_error(path.string() + ": " + std::to_string(image.width) + "x" +
                               std::to_string(image.height) + ", the index says the camera is " +
                               std::to_string(info.camera_width) + "x" +
                               std::to_string(info.camera_height));
    }
    view.frames.push_back(std::move(image));
  }
  return view;
}

BoardPoses parse_board_poses_yaml(const std::string& text, const std::string& source) {
  const YAML::Node root = runtime::yaml_parse(text, source);
  if (!root || !root.IsMap()) {
    throw std::runtime_error(source + ": expected a map with 'poses' (and optionally 'board')");
  }
  check_keys(source, root, {"board", "poses"}, "board-pose file");
  BoardPoses out;
  if (const YAML::Node b = root["board"]) out.board = read_board(source, b);
  const YAML::Node poses = required(source, root, "poses");
  if (!poses.IsSequence() || poses.size() == 0)
    fail(source, poses, "'poses' must be a non-empty list");
  for (const YAML::Node& p : poses) {
    check_keys(source, p, {"xyz_m", "rpy_deg"}, "pose");
    const std::vector<double> xyz = numbers(source, required(source, p, "xyz_m"), 3, "xyz_m");
    const std::vector<double> rpy = numbers(source, required(source, p, "rpy_deg"), 3, "rpy_deg");
    if (!(xyz[2] > 0.1)) fail(source, p, "the board must be in front of the camera (z > 0.1 m)");
    out.T_camera_board.push_back(
        pose_from_xyz_rpy({xyz[0], xyz[1], xyz[2]}, {rpy[0], rpy[1], rpy[2]}));
  }
  return out;
}

BoardPoses load_board_poses_yaml(const std::string& path) {
  return parse_board_poses_yaml(read_text(path, "board-pose file"), path);
}

}  // namespace avs::calib
