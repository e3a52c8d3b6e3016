// Local geometry for the initial alignment (paper section 6.1): neighbourhood centre and
// covariance (Eqs. 17-18), normal = eigenvector of the smallest eigenvalue, oriented; curvature
// (Eq. 19) normalised by its maximum; local reference frames (LRFs) at feature points with the
// second axis voted from the neighbours' normals (two candidates where the votes are symmetric).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "avs/matching/cloud.hpp"
#include "avs/matching/kd_tree.hpp"

namespace avs::matching {

struct FeatureConfig {
  float neighbourhood_radius_m = 0.02F;  ///< q_j: points within this radius of p_i (Eqs. 17-18)
  std::size_t min_neighbours = 5;        ///< fewer neighbours: no normal, no feature
  float curvature_threshold = 0.25F;     ///< feature point when k'_i = k_i / k_max exceeds this
  int vote_bins = 36;                    ///< angular bins of the second-axis vote
  float second_peak_ratio = 0.7F;        ///< a second vote peak this high gives a second LRF
};

/// How normals are turned: toward a viewpoint (the camera, for the S-PCD), or to agree with
/// reference normals (the mesh's outward normals, for the M-PCD).
struct NormalOrientation {
  Eigen::Vector3f viewpoint = Eigen::Vector3f::Zero();
  const Points* reference_normals = nullptr;  ///< used where non-zero; else away from the centroid
};

struct PointFeatures {
  Points normals;                                ///< e_0, oriented (zero where too few neighbours)
  std::vector<float> curvature;                  ///< k_i of Eq. 19
  std::vector<float> curvature_normalised;       ///< k'_i = k_i / k_max
  std::vector<std::uint32_t> neighbour_offsets;  ///< CSR: neighbours of i are
  std::vector<std::uint32_t> neighbours;         ///< neighbours[offsets[i] .. offsets[i+1])
};

/// A local reference frame: columns of `axes` are (normal, second axis, normal x second).
struct Lrf {
  Eigen::Matrix3f axes = Eigen::Matrix3f::Identity();
  Eigen::Vector3f origin_m = Eigen::Vector3f::Zero();
  std::uint32_t point = 0;  ///< index of the feature point
  float curvature = 0.0F;   ///< k'_i of the feature point
};

/// Eqs. 17-19 for every point of `points` (tree built over the same points).
[[nodiscard]] PointFeatures compute_features(const Points& points, const KdTree& tree,
                                             const FeatureConfig& config,
                                             const NormalOrientation& orientation);

/// LRFs at the feature points (k'_i above the threshold); one or two per point.
[[nodiscard]] std::vector<Lrf> compute_lrfs(const Points& points, const PointFeatures& features,
                                            const FeatureConfig& config);

/// A planar region of a cloud (plane normal, centroid of its points). Our addition beyond the
/// paper: section 6.1 proposes poses only from LRFs at curved feature points (Eq. 19), so a scene
/// that shows a single flat face (the cylinder end-on: a disc) gets no right hypothesis, and a
/// model's flat faces get no LRF at all. InitialAligner pairs scene patches with model faces.
struct PlanarPatch {
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  ///< unit, oriented like the input normals
  Eigen::Vector3f centroid_m = Eigen::Vector3f::Zero();
  std::size_t points = 0;
};

struct PlaneConfig {
  float normal_tolerance_rad = 0.17F;  ///< member normals within this angle of the plane's
  float offset_tolerance = 0.5F;       ///< member distance to the plane, times the spacing
  float min_extent = 1.0F;             ///< smaller in-plane standard deviation, times the spacing
  float min_fraction = 0.2F;           ///< a patch holds at least this fraction of the points ...
  std::size_t min_points = 12;         ///< ... and at least this many
  std::size_t max_patches = 3;         ///< largest patches kept
  std::size_t max_seeds = 64;          ///< seed points tried per patch (evenly spread)
};

/// Planar patches found greedily (largest first) from oriented normals (zero normals are
/// skipped): members share the seed's normal within the tolerance and lie near its plane; the
/// plane is then refitted (covariance, Eq. 18) and a patch too thin in-plane (a strip of a
/// curved surface) is dropped.
[[nodiscard]] std::vector<PlanarPatch> find_planar_patches(const Points& points,
                                                           const Points& normals,
                                                           const PlaneConfig& config,
                                                           float spacing_m);

/// Unoriented normals from the k nearest neighbours' covariance (for point-to-plane ICP).
[[nodiscard]] Points estimate_normals(const Points& points, std::size_t neighbours);

}  // namespace avs::matching
