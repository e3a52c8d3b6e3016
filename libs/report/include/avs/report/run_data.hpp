// The data contract between a run (the closed-loop simulation, `avs demo`, `avs experiments`)
// and its report: the CSV files a run folder holds, the C++ rows they map to, a writer
// (RunRecorder) so that recorders never hand-format a row, and a loader (load_run).
// docs/report.md describes every file and column; keep the two in step.
#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace avs::report {

struct Symmetry;  // summary.hpp

/// Every error of this library: the message names the file and, for rows, the line
/// ("run/frames.csv:17: column 'pan_rad': cannot parse 'abc' as a number").
class ReportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// File names inside a run folder.
inline constexpr const char* kMetaFile = "meta.csv";
inline constexpr const char* kFramesFile = "frames.csv";
inline constexpr const char* kDepthSnapshotFile = "depth_snapshot.csv";
inline constexpr const char* kDepthSnapshotRawFile = "depth_snapshot.f32";
inline constexpr const char* kCloudsSnapshotFile = "clouds_snapshot.csv";
inline constexpr const char* kSummaryFile = "summary.json";
inline constexpr const char* kIndexFile = "index.html";

/// State of model matching on one depth update.
enum class MatchState {
  none,      ///< matching off, or not started yet
  init,      ///< the initial alignment (Sec. 5.2) completed on this update; matching_ms is its time
  tracking,  ///< ICP (Sec. 5.3) ran on this update
  lost,      ///< matching gave up on this update (no pose)
};
[[nodiscard]] const char* match_state_name(MatchState state);
/// Throws ReportError naming `where` for an unknown name.
[[nodiscard]] MatchState parse_match_state(const std::string& name, const std::string& where);

/// A rigid pose in the world frame.
struct Pose {
  Eigen::Vector3d p_world_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world = Eigen::Quaterniond::Identity();  ///< unit quaternion
};

/// One row of frames.csv: one 500 Hz depth/pose update.
struct FrameRow {
  double t_s = 0.0;  ///< simulation time of the depth update
  /// Image-plane target centroid relative to the image centre (the tracking error of
  /// Fig. 8); empty when no target was segmented (target_valid = 0 in the file).
  std::optional<Eigen::Vector2d> centroid_px;
  bool in_view = false;  ///< ground truth: the target projects inside the image
  double pan_rad = 0.0;
  double tilt_rad = 0.0;
  Pose truth;                ///< ground-truth target pose (world frame)
  std::optional<Pose> meas;  ///< pose estimate produced for this update; empty when none
  MatchState match_state = MatchState::none;
  int scene_points = 0;  ///< points in the S-PCD used by matching on this update (Fig. 13a)
  std::optional<double> decode_ms;    ///< depth computation time (Sec. 4), empty if not run
  std::optional<double> tracking_ms;  ///< moments + servo law time (Sec. 3)
  std::optional<double> matching_ms;  ///< ICP time (Fig. 13b), or the initial alignment time
  /// Wall-clock (steady) seconds since the recorder started, when the row was complete: with
  /// t_s it gives the run's real-time factor. Empty in run folders written before it existed.
  std::optional<double> wall_s;
};

/// A depth map to colour like Figure 9. Row-major, top image row first, metres along the
/// optical axis; NaN or <= 0 means invalid (drawn black).
struct DepthSnapshot {
  double t_s = 0.0;
  int width = 0;
  int height = 0;
  std::vector<float> depth_m;
};

/// Scene and model points at one instant, for the Figure 14 style plot. Both clouds are in
/// the same frame (the camera frame is what the sensor saw); the model is placed at the
/// estimated pose.
struct CloudSnapshot {
  double t_s = 0.0;
  std::vector<Eigen::Vector3d> scene_m;
  std::vector<Eigen::Vector3d> model_m;
};

/// What ran. Written to meta.csv as key,value rows.
struct RunInfo {
  std::string scenario = "demo";  ///< "demo", "tracking", "no_tracking", "ken", "cube", ...
  std::string object = "ken";     ///< target model name
  /// Symmetry used for the orientation error: "none", "cube", "cylinder_x|y|z" (see
  /// summary.hpp).
  std::string symmetry = "none";
  std::string notes;  ///< free text shown in the report (no newlines)
};

/// Everything a report is made from.
struct RunData {
  std::filesystem::path dir;
  RunInfo info;
  std::vector<FrameRow> frames;
  std::optional<DepthSnapshot> depth;
  std::vector<CloudSnapshot> clouds;
  /// Problems that did not stop the load (e.g. a last row cut short by a killed writer).
  std::vector<std::string> warnings;
};

/// Reads a run folder. frames.csv and meta.csv are required; the snapshots are optional.
/// Throws ReportError with file:line for a missing column, a wrong field count, a value that
/// does not parse, a non-unit quaternion, a centroid that contradicts target_valid, ...
[[nodiscard]] RunData load_run(const std::filesystem::path& dir);

/// Writes a run folder row by row. Create one per run; every write is flushed in the
/// destructor (and by flush()). Writes the derived columns position_error_mm and
/// orientation_error_deg (for the plots) with the same functions compute_summary uses.
/// Throws ReportError when a file cannot be written.
class RunRecorder {
 public:
  RunRecorder(const std::filesystem::path& dir, const RunInfo& info);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// One depth update. Rows must come in time order.
  void write_frame(const FrameRow& row);
  /// Replaces the depth snapshot (the last one written is kept). `depth_m` holds
  /// width * height values, row-major, top row first.
  void write_depth_snapshot(double t_s, int width, int height, std::span<const float> depth_m);
  /// Appends one snapshot of scene and model clouds (Figure 14); several are shown side by
  /// side. Throws ReportError when both clouds are empty.
  void write_cloud_snapshot(double t_s, std::span<const Eigen::Vector3d> scene_m,
                            std::span<const Eigen::Vector3d> model_m);
  void flush();

  [[nodiscard]] const std::filesystem::path& dir() const { return dir_; }
  [[nodiscard]] std::size_t frames_written() const { return frames_written_; }

 private:
  std::filesystem::path dir_;
  std::unique_ptr<Symmetry> symmetry_;
  std::ofstream frames_;
  std::ofstream clouds_;
  std::size_t frames_written_ = 0;
  int cloud_snapshots_ = 0;
  double last_t_s_ = 0.0;
};

/// Column names of frames.csv in the order RunRecorder writes them.
[[nodiscard]] const std::vector<std::string>& frames_columns();

}  // namespace avs::report
