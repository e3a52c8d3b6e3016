#include "avs/report/summary.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <numbers>
#include <sstream>

namespace avs::report {
namespace {

double rad_to_deg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

/// Rotation angle of a rotation matrix, in degrees: 2 atan2(|q_vec|, |q_w|) of its
/// quaternion, which keeps precision near 0 and 180 degrees (acos of the trace does not).
double rotation_angle_deg(const Eigen::Matrix3d& r) {
  const Eigen::Quaterniond q(r);
  return rad_to_deg(2.0 * std::atan2(q.vec().norm(), std::abs(q.w())));
}

double angle_between_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // atan2 of |a x b| and a.b keeps precision near 0 and 180 degrees.
  return rad_to_deg(std::atan2(a.cross(b).norm(), a.dot(b)));
}

std::vector<double> collect(const std::vector<FrameRow>& frames, auto&& get) {
  std::vector<double> values;
  values.reserve(frames.size());
  for (const FrameRow& row : frames) {
    if (const std::optional<double> value = get(row)) values.push_back(*value);
  }
  return values;
}

void stage_stats(const std::vector<double>& values, double& median_out, double& p99_out,
                 double& max_out) {
  if (values.empty()) return;
  median_out = median(values);
  p99_out = percentile(values, 99.0);
  max_out = *std::max_element(values.begin(), values.end());
}

}  // namespace

Symmetry Symmetry::none() {
  return Symmetry{};
}

Symmetry Symmetry::cube() {
  // Signed permutation matrices with determinant +1.
  Symmetry symmetry;
  symmetry.discrete.clear();
  const std::array<std::array<int, 3>, 6> permutations{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& permutation : permutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int row = 0; row < 3; ++row) {
        m(row, permutation[static_cast<std::size_t>(row)]) = ((signs >> row) & 1) != 0 ? -1 : 1;
      }
      if (m.determinant() > 0.0) symmetry.discrete.push_back(m);
    }
  }
  return symmetry;
}

Symmetry Symmetry::cylinder(const Eigen::Vector3d& axis) {
  Symmetry symmetry;
  const Eigen::Vector3d a = axis.normalized();
  symmetry.continuous_axis = a;
  // The end-for-end flip: half a turn about any axis perpendicular to a.
  const Eigen::Vector3d perpendicular = a.unitOrthogonal();
  symmetry.discrete.push_back(
      Eigen::AngleAxisd(std::numbers::pi, perpendicular).toRotationMatrix());
  return symmetry;
}

Symmetry Symmetry::parse(const std::string& name) {
  if (name == "none") return none();
  if (name == "cube") return cube();
  if (name == "cylinder_x") return cylinder(Eigen::Vector3d::UnitX());
  if (name == "cylinder_y") return cylinder(Eigen::Vector3d::UnitY());
  if (name == "cylinder_z") return cylinder(Eigen::Vector3d::UnitZ());
  throw ReportError("unknown symmetry '" + name +
                    "' (expected none, cube, cylinder_x, cylinder_y, cylinder_z)");
}

double orientation_error_deg(const Eigen::Quaterniond& q_true, const Eigen::Quaterniond& q_meas,
                             const Symmetry& symmetry) {
  // R_d = R_true^T R_meas: the rotation taking the true body frame to the measured one.
  const Eigen::Matrix3d r_delta =
      (q_true.normalized().conjugate() * q_meas.normalized()).toRotationMatrix();
  double best = 180.0;
  for (const Eigen::Matrix3d& g : symmetry.discrete) {
    const Eigen::Matrix3d r = r_delta * g;
    // With a continuous axis a, min over theta of angle(R Rot(a, theta)) = angle(a, R a):
    // every such rotation maps a to R a, and the shortest arc from a to R a achieves it.
    const double angle = symmetry.continuous_axis ? angle_between_deg(*symmetry.continuous_axis,
                                                                      r * *symmetry.continuous_axis)
                                                  : rotation_angle_deg(r);
    best = std::min(best, angle);
  }
  return best;
}

double position_error_mm(const Pose& truth, const Pose& meas) {
  return (meas.p_world_m - truth.p_world_m).norm() * 1000.0;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return kUndefined;
  std::sort(values.begin(), values.end());
  const double rank = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(values.size() - 1);
  const auto lower = static_cast<std::size_t>(std::floor(rank));
  const std::size_t upper = std::min(lower + 1, values.size() - 1);
  const double fraction = rank - static_cast<double>(lower);
  return values[lower] + fraction * (values[upper] - values[lower]);
}

double median(std::vector<double> values) {
  return percentile(std::move(values), 50.0);
}

double rms(const std::vector<double>& values) {
  if (values.empty()) return kUndefined;
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

Summary compute_summary(const RunData& run) {
  return compute_summary(run.frames, Symmetry::parse(run.info.symmetry));
}

Summary compute_summary(const std::vector<FrameRow>& frames, const Symmetry& symmetry) {
  Summary s;
  s.frames = static_cast<double>(frames.size());
  if (frames.empty()) return s;

  // 1. Rates: updates per second over the recorded span; poses as a share of updates.
  s.duration_s = frames.back().t_s - frames.front().t_s;
  if (frames.size() >= 2 && s.duration_s > 0.0) {
    s.depth_rate_hz = static_cast<double>(frames.size() - 1) / s.duration_s;
  }
  s.pose_frames = static_cast<double>(
      std::count_if(frames.begin(), frames.end(), [](const FrameRow& r) { return r.meas; }));
  s.pose_rate_hz = s.depth_rate_hz * s.pose_frames / s.frames;
  if (frames.front().wall_s && frames.back().wall_s) {
    s.wall_duration_s = *frames.back().wall_s - *frames.front().wall_s;
    if (s.wall_duration_s > 0.0 && s.duration_s > 0.0) {
      s.real_time_factor = s.duration_s / s.wall_duration_s;
    }
  }

  // 2. Stage times. The initial alignment is reported on its own (init_ms).
  stage_stats(collect(frames, [](const FrameRow& r) { return r.decode_ms; }), s.decode_ms_median,
              s.decode_ms_p99, s.decode_ms_max);
  stage_stats(collect(frames, [](const FrameRow& r) { return r.tracking_ms; }),
              s.tracking_ms_median, s.tracking_ms_p99, s.tracking_ms_max);
  stage_stats(collect(frames,
                      [](const FrameRow& r) {
                        return r.match_state == MatchState::init ? std::nullopt : r.matching_ms;
                      }),
              s.matching_ms_median, s.matching_ms_p99, s.matching_ms_max);
  const std::vector<double> init_times = collect(frames, [](const FrameRow& r) {
    return r.match_state == MatchState::init ? r.matching_ms : std::nullopt;
  });
  s.init_count =
      static_cast<double>(std::count_if(frames.begin(), frames.end(), [](const FrameRow& r) {
        return r.match_state == MatchState::init;
      }));
  if (!init_times.empty()) s.init_ms = init_times.front();

  // 3. Pose error against ground truth, modulo the symmetry.
  std::vector<double> position_mm;
  std::vector<double> orientation_deg;
  std::vector<double> orientation_deg_kept;
  for (const FrameRow& row : frames) {
    if (!row.meas) continue;
    position_mm.push_back(position_error_mm(row.truth, *row.meas));
    const double angle = orientation_error_deg(row.truth.q_world, row.meas->q_world, symmetry);
    orientation_deg.push_back(angle);
    if (angle > kFlipThresholdDeg) {
      s.flips += 1;
    } else {
      orientation_deg_kept.push_back(angle);
    }
  }
  if (!position_mm.empty()) {
    s.position_error_mm_rms = rms(position_mm);
    s.position_error_mm_median = median(position_mm);
    s.position_error_mm_p99 = percentile(position_mm, 99.0);
    s.position_error_mm_max = *std::max_element(position_mm.begin(), position_mm.end());
    s.orientation_error_deg_rms = rms(orientation_deg);
    s.orientation_error_deg_median = median(orientation_deg);
    s.orientation_error_deg_p99 = percentile(orientation_deg, 99.0);
    s.orientation_error_deg_rms_excluding_flips = rms(orientation_deg_kept);
    s.flip_fraction = s.flips / static_cast<double>(orientation_deg.size());
  }

  // 4. Tracking: ground-truth visibility and the image-plane error of Fig. 8.
  double in_view = 0.0;
  std::vector<double> centroid_px;
  for (const FrameRow& row : frames) {
    if (row.in_view) in_view += 1.0;
    if (row.centroid_px) centroid_px.push_back(row.centroid_px->norm());
  }
  s.in_view_fraction = in_view / s.frames;
  s.target_valid_fraction = static_cast<double>(centroid_px.size()) / s.frames;
  if (!centroid_px.empty()) {
    s.centroid_error_px_rms = rms(centroid_px);
    s.centroid_error_px_max = *std::max_element(centroid_px.begin(), centroid_px.end());
  }

  // 5. S-PCD size (Fig. 13a) over the updates where matching ran.
  const std::vector<double> points =
      collect(frames, [](const FrameRow& r) -> std::optional<double> {
        if (r.match_state == MatchState::tracking) return r.scene_points;
        return std::nullopt;
      });
  if (!points.empty()) {
    s.scene_points_median = median(points);
    s.scene_points_min = *std::min_element(points.begin(), points.end());
    s.scene_points_max = *std::max_element(points.begin(), points.end());
  }
  return s;
}

const char* figure_clock_name(FigureClock clock) {
  switch (clock) {
    case FigureClock::sim:
      return "sim";
    case FigureClock::wall:
      return "wall";
    case FigureClock::none:
      break;
  }
  return "-";
}

const std::vector<SummaryField>& summary_fields() {
  constexpr FigureClock sim = FigureClock::sim;
  constexpr FigureClock wall = FigureClock::wall;
  constexpr FigureClock none = FigureClock::none;
  // Processing times are wall-clock durations of each callback on this machine, whatever the
  // run's clock; rates count updates per second of the run's (simulated) clock.
  static const std::vector<SummaryField> fields{
      {"frames", &Summary::frames, "depth updates recorded", "count", none},
      {"duration_s", &Summary::duration_s, "recorded span of simulation time", "span", sim},
      {"wall_duration_s", &Summary::wall_duration_s, "the same span on the wall clock", "span",
       wall},
      {"real_time_factor", &Summary::real_time_factor, "simulated seconds per wall-clock second",
       "ratio", none},
      {"depth_rate_hz", &Summary::depth_rate_hz, "depth updates per second", "mean rate", sim},
      {"pose_rate_hz", &Summary::pose_rate_hz, "pose estimates per second", "mean rate", sim},
      {"pose_frames", &Summary::pose_frames, "updates with a pose estimate", "count", none},
      {"decode_ms_median", &Summary::decode_ms_median, "depth computation, median", "median", wall},
      {"decode_ms_p99", &Summary::decode_ms_p99, "depth computation, 99th percentile", "p99", wall},
      {"decode_ms_max", &Summary::decode_ms_max, "depth computation, max", "max", wall},
      {"tracking_ms_median", &Summary::tracking_ms_median, "moments + servo law, median", "median",
       wall},
      {"tracking_ms_p99", &Summary::tracking_ms_p99, "moments + servo law, 99th percentile", "p99",
       wall},
      {"tracking_ms_max", &Summary::tracking_ms_max, "moments + servo law, max", "max", wall},
      {"matching_ms_median", &Summary::matching_ms_median, "matching per update, median", "median",
       wall},
      {"matching_ms_p99", &Summary::matching_ms_p99, "matching per update, 99th percentile", "p99",
       wall},
      {"matching_ms_max", &Summary::matching_ms_max, "matching per update, max", "max", wall},
      {"init_ms", &Summary::init_ms, "initial alignment time", "first", wall},
      {"init_count", &Summary::init_count, "initial alignments", "count", none},
      {"position_error_mm_rms", &Summary::position_error_mm_rms, "position error, RMS", "RMS",
       none},
      {"position_error_mm_median", &Summary::position_error_mm_median, "position error, median",
       "median", none},
      {"position_error_mm_p99", &Summary::position_error_mm_p99, "position error, 99th pct", "p99",
       none},
      {"position_error_mm_max", &Summary::position_error_mm_max, "position error, max", "max",
       none},
      {"orientation_error_deg_rms", &Summary::orientation_error_deg_rms,
       "orientation error, RMS (flips included)", "RMS", none},
      {"orientation_error_deg_median", &Summary::orientation_error_deg_median,
       "orientation error, median", "median", none},
      {"orientation_error_deg_p99", &Summary::orientation_error_deg_p99,
       "orientation error, 99th percentile", "p99", none},
      {"orientation_error_deg_rms_excluding_flips",
       &Summary::orientation_error_deg_rms_excluding_flips, "orientation error, RMS without flips",
       "RMS", none},
      {"flips", &Summary::flips, "updates with orientation error > 150 deg", "count", none},
      {"flip_fraction", &Summary::flip_fraction, "flips / updates with a pose", "fraction", none},
      {"in_view_fraction", &Summary::in_view_fraction, "target inside the image (ground truth)",
       "fraction", none},
      {"target_valid_fraction", &Summary::target_valid_fraction, "target segmented", "fraction",
       none},
      {"centroid_error_px_rms", &Summary::centroid_error_px_rms,
       "image centroid to image centre, RMS", "RMS", none},
      {"centroid_error_px_max", &Summary::centroid_error_px_max,
       "image centroid to image centre, max", "max", none},
      {"scene_points_median", &Summary::scene_points_median, "S-PCD points, median", "median",
       none},
      {"scene_points_min", &Summary::scene_points_min, "S-PCD points, min", "min", none},
      {"scene_points_max", &Summary::scene_points_max, "S-PCD points, max", "max", none},
  };
  return fields;
}

const SummaryField& summary_field(const std::string& key) {
  for (const SummaryField& field : summary_fields()) {
    if (key == field.key) return field;
  }
  throw ReportError("unknown summary key '" + key + "'");
}

double summary_value(const Summary& summary, const std::string& key) {
  return summary.*summary_field(key).member;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof(buffer), "\\u%04x", c);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string to_json(const Summary& summary, const std::string& scenario) {
  std::ostringstream out;
  out << "{\"scenario\": " << json_string(scenario);
  for (const SummaryField& field : summary_fields()) {
    const double value = summary.*field.member;
    out << ", \"" << field.key << "\": ";
    if (std::isfinite(value)) {
      char buffer[64];
      std::snprintf(buffer, sizeof(buffer), "%.9g", value);
      out << buffer;
    } else {
      out << "null";
    }
  }
  out << "}";
  return out.str();
}

}  // namespace avs::report
