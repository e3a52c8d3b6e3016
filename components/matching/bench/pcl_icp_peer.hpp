// PCL 1.13 IterativeClosestPoint as the benchmark's peer, behind a PCL-free interface so that
// PCL's slow headers are compiled in one translation unit only.
#pragma once

#include <memory>

#include "avs/matching/cloud.hpp"

namespace avs::matching::bench {

class PclIcpPeer {
 public:
  /// Builds PCL's kd-tree on the model once (as our Icp does).
  explicit PclIcpPeer(const Points& model_points_m);
  ~PclIcpPeer();
  PclIcpPeer(const PclIcpPeer&) = delete;
  PclIcpPeer& operator=(const PclIcpPeer&) = delete;

  /// Sets the scene (source) cloud; kept between calls so timing covers align() only.
  void set_scene(const Points& p_camera);

  /// `iterations` point-to-point iterations from the guess; returns T_camera_model.
  Eigen::Isometry3f align(const Eigen::Isometry3f& T_camera_model_guess, int iterations,
                          float max_correspondence_distance_m);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace avs::matching::bench
