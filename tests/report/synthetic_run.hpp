// Synthetic run data for the report tests: a seeded target trajectory with known noise,
// flips, lost targets and stage times, so that every summary figure has a value to check.
#pragma once

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "avs/report/run_data.hpp"

namespace avs::report::testing {

struct SyntheticOptions {
  unsigned seed = 7;
  int frames = 1000;
  double period_s = 0.002;  ///< 500 Hz
  int pose_every = 1;       ///< a pose on every n-th frame once tracking
  int init_frame = 10;      ///< frame on which the initial alignment completes (-1: none)
  double init_ms = 148.0;
  std::vector<int> flip_frames{200, 201, 202, 640};  ///< meas rotated 180 deg about body Y
  bool with_poses = true;
  bool with_centroid = true;
  double wall_per_sim = 5.0;  ///< wall-clock seconds per simulated second (real-time factor 0.2)
};

inline std::vector<FrameRow> make_frames(const SyntheticOptions& o) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<FrameRow> frames;
  for (int i = 0; i < o.frames; ++i) {
    FrameRow row;
    row.t_s = 1.0 + i * o.period_s;
    const double w = 2.0 * std::numbers::pi * 0.5 * row.t_s;
    row.truth.p_world_m = {0.1 * std::sin(w), 0.05 * std::cos(w), 0.8 + 0.02 * std::sin(2 * w)};
    row.truth.q_world = Eigen::AngleAxisd(0.8 * std::sin(w), Eigen::Vector3d::UnitZ()) *
                        Eigen::AngleAxisd(0.3 * std::cos(w), Eigen::Vector3d::UnitY());
    row.in_view = unit(rng) > 0.05;
    if (o.with_centroid && row.in_view && unit(rng) > 0.1) {
      row.centroid_px = Eigen::Vector2d(8.0 * noise(rng), 5.0 * noise(rng));
    }
    row.pan_rad = 0.3 * std::sin(w);
    row.tilt_rad = 0.1 * std::cos(w);
    row.wall_s = 0.25 + (row.t_s - 1.0) * o.wall_per_sim;
    row.decode_ms = 1.5 + 0.1 * noise(rng);
    row.tracking_ms = 0.05 + 0.01 * unit(rng);
    if (o.with_poses && o.init_frame >= 0 && i >= o.init_frame) {
      row.match_state = i == o.init_frame ? MatchState::init : MatchState::tracking;
      row.matching_ms = i == o.init_frame ? o.init_ms : 1.0 + 0.1 * noise(rng);
      row.scene_points = 50 + static_cast<int>(150 * unit(rng));
      if ((i - o.init_frame) % o.pose_every == 0) {
        Pose meas;
        meas.p_world_m =
            row.truth.p_world_m + 0.001 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
        const Eigen::Vector3d small = 0.01 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
        meas.q_world = row.truth.q_world * Eigen::AngleAxisd(small.norm(), small.normalized());
        for (const int f : o.flip_frames) {
          if (f == i)
            meas.q_world =
                meas.q_world * Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY());
        }
        // Either sign of the quaternion is the same rotation; the files may hold either.
        if (unit(rng) < 0.3) meas.q_world.coeffs() *= -1.0;
        row.meas = meas;
      }
    }
    frames.push_back(row);
  }
  return frames;
}

/// A depth snapshot: a tilted plane inside a disc, invalid (0 or NaN) outside.
inline std::vector<float> make_depth(int width, int height) {
  std::vector<float> depth(static_cast<std::size_t>(width * height));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double du = u - width / 2.0, dv = v - height / 2.0;
      const bool inside = du * du + dv * dv < 0.35 * 0.35 * width * width;
      float d = inside ? static_cast<float>(0.6 + 0.4 * u / width) : 0.0F;
      if (!inside && (u + v) % 2 == 0) d = std::numeric_limits<float>::quiet_NaN();
      depth[static_cast<std::size_t>(v * width + u)] = d;
    }
  }
  return depth;
}

/// A scratch folder removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              ("avs_report_test_" + std::to_string(::getpid()) + "_" + name)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    if (std::getenv("AVS_KEEP_TEST_DIRS") == nullptr) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace avs::report::testing
