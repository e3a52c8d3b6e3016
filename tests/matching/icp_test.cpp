#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>

#include <gtest/gtest.h>

#include "avs/matching/icp.hpp"
#include "avs/matching/pose_error.hpp"
#include "scene_fixture.hpp"

// Counts heap allocations so the test can check that per-frame ICP allocates nothing.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
// GCC 12 at -O1 inlines these into one another and then reports free() of memory from
// operator new as mismatched: both are ours and use malloc/free, so the pair does match.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

namespace avs::matching {
namespace {

TEST(FitRigid, RecoversAKnownTransform) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coordinate(-0.1F, 0.1F);
  Points p;
  for (int i = 0; i < 50; ++i) p.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  Eigen::Isometry3f truth = Eigen::Isometry3f::Identity();
  truth.linear() = random_rotation(11);
  truth.translation() = Eigen::Vector3f(0.1F, -0.02F, 0.5F);
  Points y;
  for (const auto& q : p) y.push_back(truth * q);
  const Eigen::Isometry3f fitted = fit_rigid(p, y, p.size());
  EXPECT_TRUE(fitted.matrix().isApprox(truth.matrix(), 1e-4F)) << fitted.matrix() << "\nvs\n"
                                                               << truth.matrix();
}

TEST(FitRigid, NeverReturnsAReflection) {
  // y is the mirror image of p: the unconstrained optimum is a reflection (det -1); Eq. 25
  // must return a proper rotation instead.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> coordinate(-0.1F, 0.1F);
  Points p;
  Points y;
  for (int i = 0; i < 40; ++i) {
    p.emplace_back(coordinate(rng), coordinate(rng), 0.3F * coordinate(rng));
    y.emplace_back(p.back().x(), p.back().y(), -p.back().z());
  }
  const Eigen::Isometry3f fitted = fit_rigid(p, y, p.size());
  EXPECT_NEAR(fitted.linear().determinant(), 1.0F, 1e-4F);
}

class IcpOnKen : public ::testing::Test {
 protected:
  void SetUp() override {
    object_ = builtin_objects()[0];
    model_ = test::model_of(object_);
    truth_ = random_object_pose(21);
    scene_ = test::scene_of(object_, model_, truth_, 21);
    guess_ = test::perturbed(truth_, {0.002F, 0.0F, 0.0F}, {0.3F, 1.0F, 0.2F}, 1.0F);
  }
  ObjectPreset object_;
  ModelCloud model_;
  Eigen::Isometry3f truth_;
  Eigen::Isometry3f guess_;
  Points scene_;
};

// Mean error over seeded poses after ICP from a 2 mm / 1 degree offset.
struct MeanError {
  double translation_mm = 0.0;
  double rotation_deg = 0.0;
  double start_rmse_mm = 0.0;
  double rmse_mm = 0.0;
};

MeanError recover_offset(const ObjectPreset& object, std::size_t model_points, IcpMetric metric) {
  ObjectPreset dense = object;
  dense.model_points = model_points;
  const ModelCloud scene_model = test::model_of(object);
  const ModelCloud model = test::model_of(dense);
  IcpConfig config;
  config.iterations = {5, 5, 20};
  config.metric = metric;
  Icp icp(model.points_m, config, model.normals);
  MeanError mean;
  constexpr int kSeeds = 10;
  for (std::uint32_t seed = 1; seed <= kSeeds; ++seed) {
    const Eigen::Isometry3f truth = random_object_pose(seed);
    const Points scene = test::scene_of(object, scene_model, truth, seed);
    const Eigen::Isometry3f guess =
        test::perturbed(truth, {0.002F, 0.0F, 0.0F}, {0.3F, 1.0F, 0.2F}, 1.0F);
    const IcpResult result = icp.align(scene, guess);
    EXPECT_TRUE(result.valid);
    EXPECT_EQ(result.iterations, 30);
    const PoseError error = pose_error(result.T_camera_model, truth, object.symmetry);
    mean.translation_mm += 1e3 * error.translation_m / kSeeds;
    mean.rotation_deg += error.rotation_deg / kSeeds;
    mean.start_rmse_mm += 1e3 * icp.align(scene, guess, {0, 0, 0}).rmse_m / kSeeds;
    mean.rmse_mm += 1e3 * result.rmse_m / kSeeds;
  }
  std::printf("%s, %zu model points, %s: %.2f mm %.2f deg, rmse %.2f -> %.2f mm\n",
              object.name.c_str(), model.points_m.size(),
              metric == IcpMetric::point_to_point ? "point-to-point" : "point-to-plane",
              mean.translation_mm, mean.rotation_deg, mean.start_rmse_mm, mean.rmse_mm);
  return mean;
}

// With the paper's sparse M-PCD (302 points, ~5 mm apart), point-to-point ICP keeps a bias of
// about 1.5 mm / 1 degree (closest points are model vertices, not the surface).
TEST_F(IcpOnKen, PointToPointRecoversTwoMillimetresAndOneDegree) {
  const MeanError mean = recover_offset(object_, object_.model_points, IcpMetric::point_to_point);
  EXPECT_LT(mean.translation_mm, 2.0);
  EXPECT_LT(mean.rotation_deg, 1.5);
  EXPECT_LT(mean.rmse_mm, mean.start_rmse_mm);
}

TEST_F(IcpOnKen, PointToPlaneIsTighter) {
  const MeanError mean = recover_offset(object_, object_.model_points, IcpMetric::point_to_plane);
  EXPECT_LT(mean.translation_mm, 1.0);
  EXPECT_LT(mean.rotation_deg, 1.2);
}

TEST_F(IcpOnKen, DenserModelIsTighterStill) {
  const MeanError mean = recover_offset(object_, 1000, IcpMetric::point_to_plane);
  EXPECT_LT(mean.translation_mm, 0.5);
  EXPECT_LT(mean.rotation_deg, 0.6);
}

TEST(IcpOnCube, PointToPlaneRecoversTheOffset) {
  const ObjectPreset cube = builtin_objects()[1];
  const MeanError mean = recover_offset(cube, cube.model_points, IcpMetric::point_to_plane);
  EXPECT_LT(mean.translation_mm, 1.0);
  EXPECT_LT(mean.rotation_deg, 0.5);
}

TEST_F(IcpOnKen, OneIterationReducesTheError) {
  Icp icp(model_.points_m, IcpConfig{}, model_.normals);  // [0, 0, 1], the paper's setting
  const IcpResult result = icp.align(scene_, guess_);
  EXPECT_EQ(result.iterations, 1);
  EXPECT_LT(pose_error(result.T_camera_model, truth_, Symmetry::none).translation_m,
            pose_error(guess_, truth_, Symmetry::none).translation_m);
}

TEST_F(IcpOnKen, ZeroIterationsOnlyEvaluates) {
  Icp icp(model_.points_m, IcpConfig{}, model_.normals);
  const IcpResult at_truth = icp.align(scene_, truth_, {0, 0, 0});
  EXPECT_TRUE(at_truth.T_camera_model.isApprox(truth_));
  EXPECT_LT(at_truth.rmse_m, icp.model_spacing_m());
  const IcpResult off = icp.align(scene_, guess_, {0, 0, 0});
  EXPECT_GT(off.rmse_m, at_truth.rmse_m);
}

// Issue 19, clutter: a hand in front of a third of the ken pulls plain ICP toward the camera;
// the trimmed ICP leaves the hand's pairs out (they are far beyond the median pair distance).
TEST_F(IcpOnKen, TrimmedIcpIsNotPulledByAHandInFrontOfTheTarget) {
  // The closed loop's setting: the dense surface samples with 15 mm pairs.
  const Points held = test::with_hand(scene_, 0.012F, 0.35F);
  IcpConfig config;
  config.iterations = {0, 0, 20};
  config.metric = IcpMetric::point_to_plane;
  config.max_correspondence_distance_m = 0.015F;
  Icp plain(model_.dense_points_m, config, model_.dense_normals);
  config.trim_factor = 2.5F;
  Icp trimmed(model_.dense_points_m, config, model_.dense_normals);
  const PoseError plain_error =
      pose_error(plain.align(held, guess_).T_camera_model, truth_, Symmetry::none);
  const IcpResult trimmed_result = trimmed.align(held, guess_);
  const PoseError trimmed_error = pose_error(trimmed_result.T_camera_model, truth_, Symmetry::none);
  std::printf(
      "hand in front of 35 %% of the ken: plain %.2f mm %.2f deg, trimmed %.2f mm %.2f deg\n",
      1e3 * plain_error.translation_m, plain_error.rotation_deg, 1e3 * trimmed_error.translation_m,
      trimmed_error.rotation_deg);
  EXPECT_GT(plain_error.translation_m, 0.002F);
  EXPECT_LT(trimmed_error.translation_m, 0.001F);
  EXPECT_LT(trimmed_error.rotation_deg, 1.0F);
  // The hand's pairs are trimmed, not the ken's: about 65 % of the scene is paired.
  EXPECT_NEAR(static_cast<double>(trimmed_result.correspondences) / held.size(), 0.65, 0.08);
  // Without clutter the trimmed ICP lands where the plain one does.
  const PoseError clean_plain =
      pose_error(plain.align(scene_, guess_).T_camera_model, truth_, Symmetry::none);
  const PoseError clean_trimmed =
      pose_error(trimmed.align(scene_, guess_).T_camera_model, truth_, Symmetry::none);
  EXPECT_NEAR(clean_trimmed.translation_m, clean_plain.translation_m, 0.0005F);
}

TEST_F(IcpOnKen, PerFrameAlignDoesNotAllocate) {
  for (const auto metric : {IcpMetric::point_to_point, IcpMetric::point_to_plane}) {
    IcpConfig config;
    config.metric = metric;
    config.iterations = {1, 1, 1};
    config.trim_factor = 2.5F;  // trimming reuses its buffers too
    Icp icp(model_.points_m, config, model_.normals);
    icp.align(scene_, guess_);  // warm-up
    const long before = g_allocations.load();
    const IcpResult result = icp.align(scene_, guess_);
    EXPECT_EQ(g_allocations.load(), before);
    EXPECT_TRUE(result.valid);
  }
}

}  // namespace
}  // namespace avs::matching
