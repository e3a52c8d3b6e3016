#include "avs/report/run_data.hpp"

#include <bit>
#include <cmath>
#include <map>

#include "avs/report/summary.hpp"
#include "csv.hpp"

namespace avs::report {
namespace {

static_assert(std::endian::native == std::endian::little,
              "depth_snapshot.f32 is little-endian float32; add byte swapping for this host");

namespace fs = std::filesystem;
using csv::format_number;

const char* const kPoseSuffixes[] = {"x_m", "y_m", "z_m", "qw", "qx", "qy", "qz"};

/// Reads the seven pose columns "<prefix>_x_m" ... "<prefix>_qz"; nullopt when all are empty.
std::optional<Pose> read_pose(const csv::Table& table, std::size_t row,
                              const std::array<std::size_t, 7>& cols, bool required) {
  std::array<std::optional<double>, 7> v;
  int present = 0;
  for (std::size_t i = 0; i < 7; ++i) {
    v[i] = table.optional_number(row, cols[i]);
    if (v[i]) ++present;
  }
  if (present == 0 && !required) return std::nullopt;
  if (present != 7) {
    for (std::size_t i = 0; i < 7; ++i) {
      if (!v[i])
        throw ReportError(table.where(row, cols[i]) + ": empty in a pose that is " +
                          (required ? "required" : "partly given (give all 7 or none)"));
    }
  }
  Pose pose;
  pose.p_world_m = {*v[0], *v[1], *v[2]};
  const Eigen::Quaterniond q(*v[3], *v[4], *v[5], *v[6]);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    throw ReportError(table.where(row, cols[3]) + ": quaternion norm " + format_number(q.norm()) +
                      " is not 1");
  }
  pose.q_world = q.normalized();
  return pose;
}

std::array<std::size_t, 7> pose_columns(const csv::Table& table, const std::string& prefix) {
  std::array<std::size_t, 7> cols{};
  for (std::size_t i = 0; i < 7; ++i) cols[i] = table.column(prefix + "_" + kPoseSuffixes[i]);
  return cols;
}

std::vector<FrameRow> read_frames(const fs::path& file, std::vector<std::string>& warnings) {
  const csv::Table table = csv::Table::read(file);
  warnings.insert(warnings.end(), table.warnings().begin(), table.warnings().end());
  const std::size_t c_t = table.column("t_s");
  const std::size_t c_cx = table.column("centroid_x_px");
  const std::size_t c_cy = table.column("centroid_y_px");
  const std::size_t c_valid = table.column("target_valid");
  const std::size_t c_in_view = table.column("in_view");
  const std::size_t c_pan = table.column("pan_rad");
  const std::size_t c_tilt = table.column("tilt_rad");
  const auto c_true = pose_columns(table, "true");
  const auto c_meas = pose_columns(table, "meas");
  const std::size_t c_state = table.column("match_state");
  const std::size_t c_points = table.column("scene_points");
  const std::size_t c_decode = table.column("decode_ms");
  const std::size_t c_tracking = table.column("tracking_ms");
  const std::size_t c_matching = table.column("matching_ms");
  const std::optional<std::size_t> c_wall = table.find_column("wall_s");  // newer folders only

  std::vector<FrameRow> frames;
  frames.reserve(table.rows());
  for (std::size_t r = 0; r < table.rows(); ++r) {
    FrameRow row;
    row.t_s = table.number(r, c_t);
    if (!frames.empty() && row.t_s < frames.back().t_s) {
      throw ReportError(table.where(r, c_t) + ": time goes backwards (" + format_number(row.t_s) +
                        " after " + format_number(frames.back().t_s) + ")");
    }
    const bool valid = table.flag(r, c_valid);
    const std::optional<double> cx = table.optional_number(r, c_cx);
    const std::optional<double> cy = table.optional_number(r, c_cy);
    if (valid != (cx.has_value() && cy.has_value()) || cx.has_value() != cy.has_value()) {
      throw ReportError(table.where(r, c_valid) +
                        ": target_valid must be 1 exactly when both centroid columns are given");
    }
    if (valid) row.centroid_px = Eigen::Vector2d(*cx, *cy);
    row.in_view = table.flag(r, c_in_view);
    row.pan_rad = table.number(r, c_pan);
    row.tilt_rad = table.number(r, c_tilt);
    row.truth = *read_pose(table, r, c_true, true);
    row.meas = read_pose(table, r, c_meas, false);
    row.match_state = parse_match_state(table.text(r, c_state), table.where(r, c_state));
    const long points = table.integer(r, c_points);
    if (points < 0) throw ReportError(table.where(r, c_points) + ": negative point count");
    row.scene_points = static_cast<int>(points);
    row.decode_ms = table.optional_number(r, c_decode);
    row.tracking_ms = table.optional_number(r, c_tracking);
    row.matching_ms = table.optional_number(r, c_matching);
    if (c_wall) row.wall_s = table.optional_number(r, *c_wall);
    if (row.match_state == MatchState::init && !row.matching_ms) {
      throw ReportError(table.where(r, c_matching) +
                        ": an 'init' row must carry the initial alignment time");
    }
    frames.push_back(row);
  }
  return frames;
}

RunInfo read_meta(const fs::path& file) {
  // key,value rows; the value is the rest of the line (free text may hold commas).
  std::ifstream in(file);
  if (!in) throw ReportError(file.string() + ": cannot open for reading");
  std::map<std::string, std::string> values;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::size_t comma = line.find(',');
    if (comma == std::string::npos) {
      throw ReportError(file.string() + ":" + std::to_string(line_number) +
                        ": expected 'key,value'");
    }
    if (line_number == 1) {
      if (line != "key,value") {
        throw ReportError(file.string() + ":1: expected the header 'key,value'");
      }
      continue;
    }
    values[line.substr(0, comma)] = line.substr(comma + 1);
  }
  RunInfo info;
  if (auto it = values.find("scenario"); it != values.end()) info.scenario = it->second;
  if (auto it = values.find("object"); it != values.end()) info.object = it->second;
  if (auto it = values.find("symmetry"); it != values.end()) info.symmetry = it->second;
  if (auto it = values.find("notes"); it != values.end()) info.notes = it->second;
  try {
    (void)Symmetry::parse(info.symmetry);
  } catch (const ReportError& e) {
    throw ReportError(file.string() + ": " + e.what());
  }
  return info;
}

DepthSnapshot read_depth(const fs::path& dir) {
  const fs::path meta_file = dir / kDepthSnapshotFile;
  const csv::Table table = csv::Table::read(meta_file);
  if (table.rows() != 1) {
    throw ReportError(meta_file.string() + ": expected exactly one row, got " +
                      std::to_string(table.rows()));
  }
  DepthSnapshot depth;
  depth.t_s = table.number(0, table.column("t_s"));
  const long width = table.integer(0, table.column("width"));
  const long height = table.integer(0, table.column("height"));
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    throw ReportError(table.where(0) + ": bad size " + std::to_string(width) + " x " +
                      std::to_string(height));
  }
  depth.width = static_cast<int>(width);
  depth.height = static_cast<int>(height);
  const fs::path raw = dir / table.text(0, table.column("file"));
  const auto expected = static_cast<std::uintmax_t>(width * height) * sizeof(float);
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(raw, ec);
  if (ec) throw ReportError(raw.string() + ": " + ec.message());
  if (size != expected) {
    throw ReportError(raw.string() + ": expected " + std::to_string(expected) + " bytes (" +
                      std::to_string(width) + " x " + std::to_string(height) + " float32), got " +
                      std::to_string(size));
  }
  depth.depth_m.resize(static_cast<std::size_t>(width * height));
  std::ifstream in(raw, std::ios::binary);
  in.read(reinterpret_cast<char*>(depth.depth_m.data()), static_cast<std::streamsize>(expected));
  if (!in) throw ReportError(raw.string() + ": read failed");
  return depth;
}

std::vector<CloudSnapshot> read_clouds(const fs::path& file, std::vector<std::string>& warnings) {
  const csv::Table table = csv::Table::read(file);
  warnings.insert(warnings.end(), table.warnings().begin(), table.warnings().end());
  const std::size_t c_snapshot = table.column("snapshot");
  const std::size_t c_t = table.column("t_s");
  const std::size_t c_cloud = table.column("cloud");
  const std::size_t c_x = table.column("x_m");
  const std::size_t c_y = table.column("y_m");
  const std::size_t c_z = table.column("z_m");
  std::vector<CloudSnapshot> clouds;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    const long index = table.integer(r, c_snapshot);
    if (index < 0 || index > static_cast<long>(clouds.size())) {
      throw ReportError(table.where(r, c_snapshot) +
                        ": snapshots must be numbered 0, 1, ... in order");
    }
    if (index == static_cast<long>(clouds.size())) {
      clouds.push_back({});
      clouds.back().t_s = table.number(r, c_t);
    }
    const Eigen::Vector3d p(table.number(r, c_x), table.number(r, c_y), table.number(r, c_z));
    const std::string& cloud = table.text(r, c_cloud);
    if (cloud == "scene") {
      clouds[static_cast<std::size_t>(index)].scene_m.push_back(p);
    } else if (cloud == "model") {
      clouds[static_cast<std::size_t>(index)].model_m.push_back(p);
    } else {
      throw ReportError(table.where(r, c_cloud) + ": expected 'scene' or 'model', got '" + cloud +
                        "'");
    }
  }
  return clouds;
}

std::ofstream open_for_writing(const fs::path& file) {
  std::ofstream out(file, std::ios::trunc);
  if (!out) throw ReportError(file.string() + ": cannot open for writing");
  return out;
}

void append_pose(std::string& line, const std::optional<Pose>& pose) {
  if (!pose) {
    line += ",,,,,,,";
    return;
  }
  const Eigen::Quaterniond& q = pose->q_world;
  for (const double v : {pose->p_world_m.x(), pose->p_world_m.y(), pose->p_world_m.z(), q.w(),
                         q.x(), q.y(), q.z()}) {
    line += ',';
    line += format_number(v);
  }
}

void append(std::string& line, const std::optional<double>& value) {
  line += ',';
  if (value) line += format_number(*value);
}

}  // namespace

const char* match_state_name(MatchState state) {
  switch (state) {
    case MatchState::none:
      return "none";
    case MatchState::init:
      return "init";
    case MatchState::tracking:
      return "tracking";
    case MatchState::lost:
      return "lost";
  }
  return "?";
}

MatchState parse_match_state(const std::string& name, const std::string& where) {
  for (const MatchState state :
       {MatchState::none, MatchState::init, MatchState::tracking, MatchState::lost}) {
    if (name == match_state_name(state)) return state;
  }
  throw ReportError(where + ": unknown match_state '" + name +
                    "' (expected none, init, tracking, lost)");
}

const std::vector<std::string>& frames_columns() {
  static const std::vector<std::string> columns{
      "t_s",         "centroid_x_px", "centroid_y_px",     "target_valid",
      "in_view",     "pan_rad",       "tilt_rad",          "true_x_m",
      "true_y_m",    "true_z_m",      "true_qw",           "true_qx",
      "true_qy",     "true_qz",       "meas_x_m",          "meas_y_m",
      "meas_z_m",    "meas_qw",       "meas_qx",           "meas_qy",
      "meas_qz",     "match_state",   "scene_points",      "decode_ms",
      "tracking_ms", "matching_ms",   "position_error_mm", "orientation_error_deg",
      "wall_s"};
  return columns;
}

RunData load_run(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw ReportError(dir.string() + ": not a run folder");
  RunData run;
  run.dir = dir;
  run.info = read_meta(dir / kMetaFile);
  run.frames = read_frames(dir / kFramesFile, run.warnings);
  if (fs::exists(dir / kDepthSnapshotFile)) run.depth = read_depth(dir);
  if (fs::exists(dir / kCloudsSnapshotFile))
    run.clouds = read_clouds(dir / kCloudsSnapshotFile, run.warnings);
  return run;
}

RunRecorder::RunRecorder(const fs::path& dir, const RunInfo& info)
    : dir_(dir), symmetry_(std::make_unique<Symmetry>(Symmetry::parse(info.symmetry))) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) throw ReportError(dir_.string() + ": cannot create: " + ec.message());
  std::ofstream meta = open_for_writing(dir_ / kMetaFile);
  for (const auto& [key, value] :
       {std::pair<const char*, const std::string&>{"scenario", info.scenario},
        {"object", info.object},
        {"symmetry", info.symmetry},
        {"notes", info.notes}}) {
    if (value.find('\n') != std::string::npos) {
      throw ReportError(std::string("RunInfo::") + key + " must be one line");
    }
  }
  meta << "key,value\nscenario," << info.scenario << "\nobject," << info.object << "\nsymmetry,"
       << info.symmetry << "\nnotes," << info.notes << "\n";
  if (!meta) throw ReportError((dir_ / kMetaFile).string() + ": write failed");

  frames_ = open_for_writing(dir_ / kFramesFile);
  const auto& columns = frames_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) frames_ << (i == 0 ? "" : ",") << columns[i];
  frames_ << '\n';
}

RunRecorder::~RunRecorder() {
  // Destructors never throw: a failed flush here was already reported by flush() if called.
  frames_.flush();
  clouds_.flush();
}

void RunRecorder::write_frame(const FrameRow& row) {
  if (frames_written_ > 0 && row.t_s < last_t_s_) {
    throw ReportError("RunRecorder: frame at t = " + format_number(row.t_s) +
                      " s comes after t = " + format_number(last_t_s_) + " s");
  }
  std::string line = format_number(row.t_s);
  append(line, row.centroid_px ? std::optional(row.centroid_px->x()) : std::nullopt);
  append(line, row.centroid_px ? std::optional(row.centroid_px->y()) : std::nullopt);
  line += row.centroid_px ? ",1" : ",0";
  line += row.in_view ? ",1" : ",0";
  append(line, row.pan_rad);
  append(line, row.tilt_rad);
  append_pose(line, row.truth);
  append_pose(line, row.meas);
  line += ',';
  line += match_state_name(row.match_state);
  line += ',' + std::to_string(row.scene_points);
  append(line, row.decode_ms);
  append(line, row.tracking_ms);
  append(line, row.matching_ms);
  if (row.meas) {
    append(line, position_error_mm(row.truth, *row.meas));
    append(line, orientation_error_deg(row.truth.q_world, row.meas->q_world, *symmetry_));
  } else {
    line += ",,";
  }
  append(line, row.wall_s);
  frames_ << line << '\n';
  if (!frames_) throw ReportError((dir_ / kFramesFile).string() + ": write failed");
  ++frames_written_;
  last_t_s_ = row.t_s;
}

void RunRecorder::write_depth_snapshot(double t_s, int width, int height,
                                       std::span<const float> depth_m) {
  if (width <= 0 || height <= 0 ||
      depth_m.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw ReportError("RunRecorder::write_depth_snapshot: " + std::to_string(depth_m.size()) +
                      " values for " + std::to_string(width) + " x " + std::to_string(height));
  }
  {
    std::ofstream raw(dir_ / kDepthSnapshotRawFile, std::ios::binary | std::ios::trunc);
    raw.write(reinterpret_cast<const char*>(depth_m.data()),
              static_cast<std::streamsize>(depth_m.size_bytes()));
    if (!raw) throw ReportError((dir_ / kDepthSnapshotRawFile).string() + ": write failed");
  }
  std::ofstream meta = open_for_writing(dir_ / kDepthSnapshotFile);
  meta << "t_s,width,height,file\n"
       << format_number(t_s) << ',' << width << ',' << height << ',' << kDepthSnapshotRawFile
       << '\n';
  if (!meta) throw ReportError((dir_ / kDepthSnapshotFile).string() + ": write failed");
}

void RunRecorder::write_cloud_snapshot(double t_s, std::span<const Eigen::Vector3d> scene_m,
                                       std::span<const Eigen::Vector3d> model_m) {
  if (scene_m.empty() && model_m.empty()) {
    throw ReportError("RunRecorder::write_cloud_snapshot: both clouds are empty");
  }
  if (!clouds_.is_open()) {
    clouds_ = open_for_writing(dir_ / kCloudsSnapshotFile);
    clouds_ << "snapshot,t_s,cloud,x_m,y_m,z_m\n";
  }
  const std::string prefix = std::to_string(cloud_snapshots_) + ',' + format_number(t_s) + ',';
  for (const auto& [name, cloud] : {std::pair{"scene", scene_m}, std::pair{"model", model_m}}) {
    for (const Eigen::Vector3d& p : cloud) {
      clouds_ << prefix << name << ',' << format_number(p.x()) << ',' << format_number(p.y()) << ','
              << format_number(p.z()) << '\n';
    }
  }
  if (!clouds_) throw ReportError((dir_ / kCloudsSnapshotFile).string() + ": write failed");
  ++cloud_snapshots_;
}

void RunRecorder::flush() {
  frames_.flush();
  if (clouds_.is_open()) clouds_.flush();
  if (!frames_ || (clouds_.is_open() && !clouds_)) {
    throw ReportError(dir_.string() + ": flush failed");
  }
}

}  // namespace avs::report
