// compute_summary against values computed independently here (straight loops, other formulas).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "avs/report/summary.hpp"
#include "synthetic_run.hpp"

namespace avs::report {
namespace {

using testing::make_frames;
using testing::SyntheticOptions;

double deg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

/// Rotation angle between two unit quaternions: 2 acos |<q1, q2>|.
double quaternion_angle_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return deg(2.0 * std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))));
}

/// The 24 cube rotations, generated as the closure of quarter turns about x and y.
std::vector<Eigen::Quaterniond> cube_group_by_closure() {
  const Eigen::Quaterniond gx(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond gy(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()));
  std::vector<Eigen::Quaterniond> group{Eigen::Quaterniond::Identity()};
  for (std::size_t i = 0; i < group.size(); ++i) {
    for (const auto& g : {gx, gy}) {
      const Eigen::Quaterniond q = group[i] * g;
      const bool known = std::any_of(group.begin(), group.end(), [&](const auto& p) {
        return quaternion_angle_deg(p, q) < 1e-6;
      });
      if (!known) group.push_back(q);
    }
  }
  return group;
}

TEST(Statistics, PercentileMatchesTheType7Definition) {
  std::vector<double> values;
  for (int i = 100; i >= 1; --i) values.push_back(i);  // 1..100, unsorted
  // rank = 0.99 * 99 = 98.01 -> 99 + 0.01 * (100 - 99)
  EXPECT_NEAR(percentile(values, 99.0), 99.01, 1e-12);
  EXPECT_DOUBLE_EQ(median(values), 50.5);
  EXPECT_DOUBLE_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(percentile({5.0}, 99.0), 5.0);
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_DOUBLE_EQ(rms({3.0, 4.0}), std::sqrt(12.5));
}

TEST(OrientationError, NoSymmetryIsTheRelativeRotationAngle) {
  std::srand(11);  // Eigen's UnitRandom draws from std::rand
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond a = Eigen::Quaterniond::UnitRandom();
    const Eigen::Quaterniond b = Eigen::Quaterniond::UnitRandom();
    EXPECT_NEAR(orientation_error_deg(a, b, Symmetry::none()), quaternion_angle_deg(a, b), 1e-6);
  }
}

TEST(OrientationError, CubeIsTheMinimumOverItsTwentyFourRotations) {
  const auto group = cube_group_by_closure();
  ASSERT_EQ(group.size(), 24U);
  const Symmetry cube = Symmetry::cube();
  ASSERT_EQ(cube.discrete.size(), 24U);
  std::srand(3);  // Eigen's UnitRandom draws from std::rand
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond a = Eigen::Quaterniond::UnitRandom();
    const Eigen::Quaterniond b = Eigen::Quaterniond::UnitRandom();
    double expected = 180.0;
    for (const auto& g : group) expected = std::min(expected, quaternion_angle_deg(a, b * g));
    EXPECT_NEAR(orientation_error_deg(a, b, cube), expected, 1e-6);
  }
  // A quarter turn about a face normal is no error for a cube, 90 degrees for the ken.
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Quaterniond b =
      a * Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(orientation_error_deg(a, b, cube), 0.0, 1e-6);
  EXPECT_NEAR(orientation_error_deg(a, b, Symmetry::none()), 90.0, 1e-6);
}

TEST(OrientationError, CylinderIgnoresSpinAndEndFlip) {
  const Symmetry cylinder = Symmetry::parse("cylinder_z");
  std::srand(5);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Quaterniond a = Eigen::Quaterniond::UnitRandom();
    const Eigen::Quaterniond b = Eigen::Quaterniond::UnitRandom();
    // Brute force: every spin about z in 0.05 degree steps, with and without the end flip.
    double expected = 180.0;
    for (int flip = 0; flip < 2; ++flip) {
      const Eigen::Quaterniond f(
          Eigen::AngleAxisd(flip * std::numbers::pi, Eigen::Vector3d::UnitX()));
      for (int k = 0; k < 7200; ++k) {
        const Eigen::Quaterniond spin(
            Eigen::AngleAxisd(k * std::numbers::pi / 3600, Eigen::Vector3d::UnitZ()));
        expected = std::min(expected, quaternion_angle_deg(a, b * f * spin));
      }
    }
    EXPECT_NEAR(orientation_error_deg(a, b, cylinder), expected, 0.03);
  }
  const Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  EXPECT_NEAR(
      orientation_error_deg(a, Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ())),
                            cylinder),
      0.0, 1e-6);
  EXPECT_NEAR(
      orientation_error_deg(a, Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX())),
                            cylinder),
      deg(0.1), 1e-6);
  EXPECT_THROW((void)Symmetry::parse("sphere"), ReportError);
}

TEST(Summary, EqualsIndependentlyComputedFigures) {
  SyntheticOptions options;
  options.pose_every = 2;
  const std::vector<FrameRow> frames = make_frames(options);
  const Summary s = compute_summary(frames, Symmetry::none());

  // Independent computation.
  const double n = static_cast<double>(frames.size());
  const double duration = frames.back().t_s - frames.front().t_s;
  double poses = 0, in_view = 0, valid = 0, sum_p2 = 0, sum_o2 = 0, sum_c2 = 0, flips = 0;
  double max_p = 0;
  std::vector<double> decode, matching, points;
  for (const FrameRow& f : frames) {
    in_view += f.in_view ? 1 : 0;
    if (f.centroid_px) {
      valid += 1;
      sum_c2 += f.centroid_px->squaredNorm();
    }
    decode.push_back(*f.decode_ms);
    if (f.match_state == MatchState::tracking) {
      matching.push_back(*f.matching_ms);
      points.push_back(f.scene_points);
    }
    if (!f.meas) continue;
    poses += 1;
    const double p_mm = 1000.0 * (f.meas->p_world_m - f.truth.p_world_m).norm();
    const double o_deg = quaternion_angle_deg(f.truth.q_world, f.meas->q_world);
    sum_p2 += p_mm * p_mm;
    sum_o2 += o_deg * o_deg;
    max_p = std::max(max_p, p_mm);
    flips += o_deg > 150.0 ? 1 : 0;
  }
  std::sort(decode.begin(), decode.end());
  std::sort(matching.begin(), matching.end());

  EXPECT_EQ(s.frames, n);
  EXPECT_NEAR(s.duration_s, 0.002 * (n - 1), 1e-9);
  EXPECT_NEAR(s.depth_rate_hz, 500.0, 1e-6);
  EXPECT_NEAR(s.pose_rate_hz, 500.0 * poses / n, 1e-6);
  EXPECT_NEAR(s.pose_rate_hz, (n - options.init_frame) / 2.0 / duration, 0.6);  // ~250 Hz
  EXPECT_NEAR(s.decode_ms_median, 0.5 * (decode[499] + decode[500]), 1e-12);
  const double rank = 0.99 * (decode.size() - 1);
  const auto lo = static_cast<std::size_t>(rank);
  EXPECT_NEAR(s.decode_ms_p99, decode[lo] + (rank - lo) * (decode[lo + 1] - decode[lo]), 1e-12);
  EXPECT_DOUBLE_EQ(s.decode_ms_max, decode.back());
  EXPECT_DOUBLE_EQ(s.matching_ms_max, matching.back());
  EXPECT_LT(s.matching_ms_max, 100.0) << "the 148 ms initial alignment must not count as ICP time";
  EXPECT_DOUBLE_EQ(s.init_ms, options.init_ms);
  EXPECT_EQ(s.init_count, 1);
  EXPECT_NEAR(s.position_error_mm_rms, std::sqrt(sum_p2 / poses), 1e-9);
  EXPECT_NEAR(s.position_error_mm_max, max_p, 1e-9);
  EXPECT_NEAR(s.orientation_error_deg_rms, std::sqrt(sum_o2 / poses), 1e-6);
  // Flip frames 200-202 and 640: those with a pose (pose_every = 2 from frame 10: even ones).
  EXPECT_EQ(flips, 3);
  EXPECT_EQ(s.flips, flips);
  EXPECT_NEAR(s.flip_fraction, flips / poses, 1e-12);
  EXPECT_LT(s.orientation_error_deg_rms_excluding_flips, 3.0);
  EXPECT_NEAR(s.in_view_fraction, in_view / n, 1e-12);
  EXPECT_NEAR(s.target_valid_fraction, valid / n, 1e-12);
  EXPECT_NEAR(s.centroid_error_px_rms, std::sqrt(sum_c2 / valid), 1e-9);
  EXPECT_EQ(s.scene_points_min, *std::min_element(points.begin(), points.end()));
  EXPECT_EQ(s.scene_points_max, *std::max_element(points.begin(), points.end()));
}

TEST(Summary, SymmetryOfTheRunChangesFlips) {
  SyntheticOptions options;
  const std::vector<FrameRow> frames = make_frames(options);
  // Half a turn about body Y is a symmetry of a cube: no flips there, four for the ken.
  EXPECT_EQ(compute_summary(frames, Symmetry::none()).flips, 4);
  EXPECT_EQ(compute_summary(frames, Symmetry::cube()).flips, 0);
}

TEST(Summary, RunWithoutMatchingHasNoPoseFigures) {
  SyntheticOptions options;
  options.with_poses = false;
  const Summary s = compute_summary(make_frames(options), Symmetry::none());
  EXPECT_EQ(s.pose_frames, 0);
  EXPECT_EQ(s.pose_rate_hz, 0.0);
  EXPECT_TRUE(std::isnan(s.position_error_mm_rms));
  EXPECT_TRUE(std::isnan(s.init_ms));
  EXPECT_TRUE(std::isnan(s.matching_ms_median));
  EXPECT_FALSE(std::isnan(s.centroid_error_px_rms));
  const std::string json = to_json(s, "tracking");
  EXPECT_NE(json.find("\"position_error_mm_rms\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"depth_rate_hz\": 500"), std::string::npos) << json;
}

TEST(Summary, RealTimeFactorFromTheWallClockBesideTheSimulatedOne) {
  SyntheticOptions o;
  o.wall_per_sim = 4.0;
  const Summary s = compute_summary(make_frames(o), Symmetry::none());
  EXPECT_NEAR(s.duration_s, 999 * 0.002, 1e-9);
  EXPECT_NEAR(s.wall_duration_s, 4.0 * 999 * 0.002, 1e-9);
  EXPECT_NEAR(s.real_time_factor, 0.25, 1e-12);
  // A run folder from before wall_s: the factor is unknown, never made up.
  std::vector<FrameRow> old = make_frames({});
  for (FrameRow& row : old) row.wall_s.reset();
  const Summary unknown = compute_summary(old, Symmetry::none());
  EXPECT_TRUE(std::isnan(unknown.real_time_factor));
  EXPECT_TRUE(std::isnan(unknown.wall_duration_s));
}

TEST(Summary, EveryFieldSaysItsStatisticAndClock) {
  for (const SummaryField& field : summary_fields()) {
    EXPECT_NE(std::string(field.statistic), "") << field.key;
    const std::string key = field.key;
    // Processing times are wall-clock, rates per simulated second, errors neither.
    if (key.find("_ms_") != std::string::npos || key == "init_ms") {
      EXPECT_EQ(field.clock, FigureClock::wall) << key;
    }
    if (key.ends_with("_hz")) {
      EXPECT_EQ(field.clock, FigureClock::sim) << key;
    }
    if (key.find("error") != std::string::npos) {
      EXPECT_EQ(field.clock, FigureClock::none) << key;
    }
    if (key.ends_with("_rms")) {
      EXPECT_EQ(std::string(field.statistic), "RMS") << key;
    }
    if (key.ends_with("_p99")) {
      EXPECT_EQ(std::string(field.statistic), "p99") << key;
    }
    if (key.ends_with("_median")) {
      EXPECT_EQ(std::string(field.statistic), "median") << key;
    }
  }
}

TEST(Summary, EveryFieldIsInTheJson) {
  const Summary s = compute_summary(make_frames({}), Symmetry::none());
  const std::string json = to_json(s, "ken");
  for (const SummaryField& field : summary_fields()) {
    EXPECT_NE(json.find("\"" + std::string(field.key) + "\": "), std::string::npos) << field.key;
    EXPECT_EQ(summary_value(s, field.key), s.*field.member);
  }
  EXPECT_THROW((void)summary_value(s, "no_such_key"), ReportError);
  EXPECT_EQ(json_string("a\"b\\c\n"), "\"a\\\"b\\\\c\\u000a\"");
}

}  // namespace
}  // namespace avs::report
