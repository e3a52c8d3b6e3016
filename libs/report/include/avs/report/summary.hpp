// The figures of a run, computed from its frames: rates, stage times (median, p99, max),
// tracking error in the image, pose error against ground truth modulo the object's
// symmetry, flips. Every number in summary.json, the tables and index.html comes from here.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "avs/report/run_data.hpp"

namespace avs::report {

/// The rotations that leave the object unchanged (body frame): a discrete set, optionally
/// combined with every rotation about one body axis (a cylinder).
struct Symmetry {
  std::vector<Eigen::Matrix3d> discrete{Eigen::Matrix3d::Identity()};  ///< includes identity
  std::optional<Eigen::Vector3d> continuous_axis;                      ///< unit, body frame

  [[nodiscard]] static Symmetry none();
  [[nodiscard]] static Symmetry cube();  ///< the 24 proper rotations of a cube
  /// Any rotation about `axis` and the end-for-end flip (a cylinder with equal ends).
  [[nodiscard]] static Symmetry cylinder(const Eigen::Vector3d& axis);
  /// "none", "cube", "cylinder_x", "cylinder_y", "cylinder_z"; throws ReportError otherwise.
  [[nodiscard]] static Symmetry parse(const std::string& name);
};

/// Angle in degrees of q_true^-1 q_meas g, minimised over the symmetries g (for a
/// continuous axis a: the angle between a and R_true^T R_meas g a, which is that minimum).
[[nodiscard]] double orientation_error_deg(const Eigen::Quaterniond& q_true,
                                           const Eigen::Quaterniond& q_meas,
                                           const Symmetry& symmetry);

/// Distance between the measured and true positions in millimetres.
[[nodiscard]] double position_error_mm(const Pose& truth, const Pose& meas);

/// Frames whose orientation error exceeds this count as flips (the ken's 180-degree
/// reversal about Y in Sec. 7.2.1).
inline constexpr double kFlipThresholdDeg = 150.0;

/// Linear-interpolated percentile (the "type 7" definition of R and NumPy's default):
/// p in [0, 100]. NaN for an empty sample. The input need not be sorted.
[[nodiscard]] double percentile(std::vector<double> values, double p);
[[nodiscard]] double median(std::vector<double> values);
[[nodiscard]] double rms(const std::vector<double>& values);  ///< NaN for an empty sample

inline constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();

/// The figures of a run. NaN marks a figure the run has no data for (e.g. pose errors when
/// matching was off); it is written as null in JSON and "-" in tables.
struct Summary {
  double frames = 0;               ///< depth updates (rows of frames.csv)
  double duration_s = kUndefined;  ///< last minus first t_s
  /// Wall-clock time over the same rows (last minus first wall_s), and the run's real-time
  /// factor duration_s / wall_duration_s (0.2: a second of simulation took 5 s). NaN for a
  /// run folder without wall_s.
  double wall_duration_s = kUndefined;
  double real_time_factor = kUndefined;
  double depth_rate_hz = kUndefined;
  double pose_rate_hz = kUndefined;  ///< poses per second (the ICP rate of Sec. 7.2)
  double pose_frames = 0;            ///< frames with a pose estimate
  double decode_ms_median = kUndefined, decode_ms_p99 = kUndefined, decode_ms_max = kUndefined;
  double tracking_ms_median = kUndefined, tracking_ms_p99 = kUndefined,
         tracking_ms_max = kUndefined;
  /// Per-update matching (ICP) time; rows with match_state = init are excluded.
  double matching_ms_median = kUndefined, matching_ms_p99 = kUndefined,
         matching_ms_max = kUndefined;
  double init_ms = kUndefined;  ///< the first initial alignment's time
  double init_count = 0;        ///< initial alignments (1 + re-initialisations)
  double position_error_mm_rms = kUndefined, position_error_mm_median = kUndefined,
         position_error_mm_p99 = kUndefined, position_error_mm_max = kUndefined;
  double orientation_error_deg_rms = kUndefined, orientation_error_deg_median = kUndefined,
         orientation_error_deg_p99 = kUndefined;
  /// RMS over the frames that are not flips.
  double orientation_error_deg_rms_excluding_flips = kUndefined;
  double flips = 0;  ///< frames with orientation error > kFlipThresholdDeg
  double flip_fraction = kUndefined;
  double in_view_fraction = kUndefined;       ///< ground truth, all frames
  double target_valid_fraction = kUndefined;  ///< frames with a segmented target
  double centroid_error_px_rms = kUndefined;  ///< over frames with a target
  double centroid_error_px_max = kUndefined;
  double scene_points_median = kUndefined, scene_points_min = kUndefined,
         scene_points_max = kUndefined;  ///< over frames where matching ran
};

/// Which clock a figure is measured on: rates per second of simulated time, processing times
/// on this machine's wall clock, errors against ground truth at the simulated instants.
enum class FigureClock { sim, wall, none };
[[nodiscard]] const char* figure_clock_name(FigureClock clock);  ///< "sim", "wall", "-"

/// One named figure of a summary (keys carry units, e.g. "decode_ms_p99").
struct SummaryField {
  const char* key;
  double Summary::*member;
  const char* description;
  const char* statistic;  ///< over the run's updates: "median", "p99", "max", "RMS", "rate", ...
  FigureClock clock;
};
/// Every field, in the order of summary.json.
[[nodiscard]] const std::vector<SummaryField>& summary_fields();
/// The field named `key`; throws ReportError for an unknown key.
[[nodiscard]] const SummaryField& summary_field(const std::string& key);
/// Value of `key`; throws ReportError for an unknown key.
[[nodiscard]] double summary_value(const Summary& summary, const std::string& key);

/// Computes every figure from the frames; the symmetry comes from run.info.symmetry.
[[nodiscard]] Summary compute_summary(const RunData& run);
[[nodiscard]] Summary compute_summary(const std::vector<FrameRow>& frames,
                                      const Symmetry& symmetry);

/// `text` as a JSON string literal, quotes included.
[[nodiscard]] std::string json_string(const std::string& text);

/// One JSON object: {"scenario": "...", "frames": 1000, ...}; NaN as null.
[[nodiscard]] std::string to_json(const Summary& summary, const std::string& scenario);

}  // namespace avs::report
