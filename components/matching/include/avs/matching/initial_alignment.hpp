// Initial (global) alignment by local reference frames (paper section 6.1, Eqs. 17-20), then
// verification: the best LRF-pair hypotheses (and their end-for-end turns) are refined by ICP
// and re-scored on the whole S-PCD against the dense model surface, with a free-space term (model
// surface the pose shows where the scene has none), so a flipped match (the ken's big cup on its
// small cup) loses to the right one. Beyond the paper, planar scene patches are also paired with
// the model's flat faces (plane hypotheses), for scenes that show one flat face.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "avs/matching/cloud.hpp"
#include "avs/matching/distance_grid.hpp"
#include "avs/matching/features.hpp"
#include "avs/matching/icp.hpp"
#include "avs/matching/model_cloud.hpp"

namespace avs::matching {

struct InitialAlignmentConfig {
  FeatureConfig scene_features;      ///< radius 0 = 2.5 x the model's mean point spacing
  FeatureConfig model_features;      ///< radius 0 = 2.5 x the model's mean point spacing
  float scene_lrf_rate = 0.1F;       ///< scene LRFs kept (paper: 0.1) ...
  std::size_t min_scene_lrfs = 40;   ///< ... but at least this many when available
  std::size_t score_points = 80;     ///< scene points that score each hypothesis
  float score_truncation_m = 0.02F;  ///< closest-point distances are clamped to this
  /// Early termination: a hypothesis whose first score_probe_points (random) points cost more
  /// than score_probe_slack times their share of the current limit is abandoned.
  std::size_t score_probe_points = 16;
  float score_probe_slack = 1.5F;
  /// Cell of the tabulated closest-point distance to the dense model surface that scores the
  /// hypotheses (DistanceGrid, built in the constructor).
  float distance_cell_m = 0.002F;
  std::size_t refine_candidates = 6;  ///< best distinct hypotheses refined by ICP
  std::array<int, 3> refine_iterations{4, 4, 6};
  /// Refined candidates (best by the scene-to-model distance) that get the dense verification.
  std::size_t verify_candidates = 3;
  IcpMetric refine_metric = IcpMetric::point_to_plane;
  float verify_truncation_m = 0.01F;  ///< truncation of the final scores
  /// Trimmed ICP in the refinement and verification (IcpConfig::trim_factor; 0 = off).
  float trim_factor = 0.0F;
  /// The scene term of the screening and the verification is the mean over this share of the
  /// scene points closest to the model (issue 19, clutter: a hand's points cost every
  /// hypothesis, the true one too, and let a pose that fits the hand win); 1 = all points.
  float score_trim_fraction = 1.0F;
  /// Weight of the visibility term: mean distance from the model points the refined pose shows
  /// to the camera to their closest scene points (self-occluded points count too; superseded
  /// by the free-space term, off by default).
  float visibility_weight = 0.0F;
  /// Weight of the free-space term: the fraction of the model points the refined pose shows to
  /// the camera that lie where the scene shows nothing or in front of the observed surface
  /// (times verify_truncation_m). It tells the ken's big cup from its small cup.
  float free_space_weight = 1.0F;
  float free_space_tolerance_m = 0.01F;           ///< depth margin of the free-space test
  std::array<int, 3> verify_iterations{0, 0, 5};  ///< ICP on the dense model before scoring
  /// The best few hypotheses are also tried turned by 180 degrees about each principal axis of
  /// the model (through its centroid): the end-for-end flips LRFs confuse.
  std::size_t flip_candidates = 2;
  /// Plane hypotheses (our addition beyond the paper, which proposes poses from LRF pairs only,
  /// Eq. 20): every large planar scene patch is paired with every flat model face (the face's
  /// outward normal turned onto the patch's camera-facing normal, centroids matched) at
  /// plane_rotations turns about the normal; the best plane_candidates of them join the refinement
  /// and verification. This is what finds the cylinder seen end-on (a flat disc: no model LRF on
  /// the flat cap). 0 turns it off.
  std::size_t plane_rotations = 24;
  std::size_t plane_candidates = 2;
  PlaneConfig scene_planes{};  ///< large patches only (20 % of the S-PCD): cheap in the common case
  PlaneConfig model_faces{.normal_tolerance_rad = 0.09F,
                          .offset_tolerance = 0.5F,
                          .min_extent = 1.0F,
                          .min_fraction = 0.03F,
                          .min_points = 8,
                          .max_patches = 12,
                          .max_seeds = 256};
  std::uint32_t seed = 1;  ///< for the LRF down-sampling
};

struct InitialAlignmentResult {
  Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
  float score_m = 0.0F;  ///< verification score of the chosen, refined pose (lower is better)
  float rmse_m = 0.0F;   ///< ICP residual of the chosen pose
  std::size_t scene_lrfs = 0;
  std::size_t model_lrfs = 0;
  std::size_t hypotheses = 0;        ///< LRF pairs scored
  std::size_t scene_planes = 0;      ///< planar scene patches (plane hypotheses)
  std::size_t plane_hypotheses = 0;  ///< plane/face pairs x turns scored
  std::size_t candidates = 0;        ///< hypotheses refined and verified
  float features_ms = 0.0F;          ///< wall time: scene features and LRFs (Eqs. 17-19)
  float scoring_ms = 0.0F;           ///< wall time: LRF-pair scoring (Eq. 20)
  float verify_ms = 0.0F;            ///< wall time: refinement and verification
  bool valid = false;                ///< false when the scene has too few points or LRFs
};

/// A pose after the verification's ICP on the dense model samples, and its score.
struct VerifiedPose {
  Eigen::Isometry3f T_camera_model = Eigen::Isometry3f::Identity();
  float score_m = std::numeric_limits<float>::infinity();  ///< lower is better
  float scene_term_m = 0.0F;           ///< mean truncated scene-to-model distance
  float free_space_violations = 0.0F;  ///< fraction of the shown model points in free space
  float rmse_m = 0.0F;
};

namespace detail {
class RangeImage;
}

/// Holds the model's features and LRFs (computed once) and aligns scenes to it.
class InitialAligner {
 public:
  explicit InitialAligner(const ModelCloud& model, InitialAlignmentConfig config = {});

  [[nodiscard]] InitialAlignmentResult align(const Points& p_camera);

  /// The verification step alone from a given pose (for diagnostics and tests).
  [[nodiscard]] VerifiedPose verify(const Points& p_camera,
                                    const Eigen::Isometry3f& T_camera_model_guess);

  [[nodiscard]] const std::vector<Lrf>& model_lrfs() const { return model_lrfs_; }
  /// The model's flat faces (outward normals) the plane hypotheses pair scene planes with.
  [[nodiscard]] const std::vector<PlanarPatch>& model_faces() const { return model_faces_; }
  /// LRFs of the last scene (all, and the down-sampled ones used), for figures.
  [[nodiscard]] const std::vector<Lrf>& scene_lrfs() const { return scene_lrfs_; }
  [[nodiscard]] const std::vector<Lrf>& scene_lrfs_used() const { return scene_lrfs_used_; }
  [[nodiscard]] const InitialAlignmentConfig& config() const { return config_; }

 private:
  struct Hypothesis {
    Eigen::Isometry3f T_model_camera;
    float score;
  };
  [[nodiscard]] VerifiedPose verify(const Points& p_camera, const KdTree& scene_tree,
                                    const detail::RangeImage& range,
                                    const Eigen::Isometry3f& T_camera_model_guess);
  [[nodiscard]] float scene_distance(const Points& p_camera,
                                     const Eigen::Isometry3f& T_model_camera);
  [[nodiscard]] float score(const Points& p_camera, const std::vector<std::uint32_t>& subset,
                            const Eigen::Isometry3f& T_model_camera, float give_up_above) const;

  InitialAlignmentConfig config_;
  KdTree model_tree_;
  KdTree dense_tree_;  // dense samples (the M-PCD itself when the model has none)
  Points dense_normals_;
  DistanceGrid distance_;                         // truncated distance to the dense model surface
  float spacing_m_ = 0.0F;                        // the M-PCD's mean point spacing
  std::array<Eigen::Isometry3f, 3> flips_model_;  // 180-degree turns about the principal axes
  std::vector<Lrf> model_lrfs_;
  std::vector<PlanarPatch> model_faces_;
  std::vector<Lrf> scene_lrfs_;
  std::vector<Lrf> scene_lrfs_used_;
  Icp refine_;
  Icp verify_;
  std::vector<float> distances_m_;  // scene_distance's per-point distances (trimmed mean)
};

}  // namespace avs::matching
