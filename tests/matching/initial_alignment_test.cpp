#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "avs/matching/initial_alignment.hpp"
#include "avs/matching/pose_error.hpp"
#include "scene_fixture.hpp"

namespace avs::matching {
namespace {

constexpr int kPoses = 50;

struct Outcome {
  int successes = 0;
  int flips = 0;  // rotation error above 90 degrees (the ken's end-for-end confusion)
  int attempts = 0;
};

Outcome run(const ObjectPreset& object, std::uint32_t first_seed) {
  const ModelCloud model = test::model_of(object);
  InitialAligner aligner(model);
  IcpConfig final_config;
  final_config.iterations = {0, 0, 10};
  final_config.metric = IcpMetric::point_to_plane;
  Icp icp(model.points_m, final_config, model.normals);
  Outcome outcome;
  for (int k = 0; k < kPoses; ++k) {
    const std::uint32_t seed = first_seed + static_cast<std::uint32_t>(k);
    const Eigen::Isometry3f truth = random_object_pose(seed);
    const Points scene = test::scene_of(object, model, truth, seed);
    const InitialAlignmentResult initial = aligner.align(scene);
    ++outcome.attempts;
    if (!initial.valid) continue;
    const IcpResult refined = icp.align(scene, initial.T_camera_model);
    const PoseError error = pose_error(refined.T_camera_model, truth, object.symmetry);
    if (error.rotation_deg < 5.0F && error.translation_m < 0.005F) ++outcome.successes;
    if (error.rotation_deg > 90.0F) ++outcome.flips;
    if (error.rotation_deg >= 5.0F || error.translation_m >= 0.005F) {
      std::printf("  %s seed %u: %.1f deg %.1f mm (scene %zu pts, %zu lrfs)\n", object.name.c_str(),
                  seed, static_cast<double>(error.rotation_deg),
                  1e3 * static_cast<double>(error.translation_m), scene.size(), initial.scene_lrfs);
    }
  }
  return outcome;
}

class InitialAlignment : public ::testing::TestWithParam<int> {};

TEST_P(InitialAlignment, SucceedsOnFiftyRandomPoses) {
  const ObjectPreset object = builtin_objects()[static_cast<std::size_t>(GetParam())];
  const Outcome outcome = run(object, 1000U * static_cast<std::uint32_t>(GetParam() + 1));
  std::printf("%s: %d / %d successes, %d flips\n", object.name.c_str(), outcome.successes,
              outcome.attempts, outcome.flips);
  EXPECT_GE(outcome.successes, (95 * kPoses + 99) / 100) << object.name;
  if (object.name == "ken") {
    EXPECT_EQ(outcome.flips, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(BuiltinObjects, InitialAlignment, ::testing::Values(0, 1, 2),
                         [](const auto& info) {
                           return builtin_objects()[static_cast<std::size_t>(info.param)].name;
                         });

// The benchmark's seeds and two more sets: the ken must never come out end-for-end.
TEST(InitialAlignment, KenNeverFlipsOnTwoHundredPoses) {
  const ObjectPreset ken = builtin_objects()[0];
  int successes = 0;
  int flips = 0;
  for (const std::uint32_t first_seed : {2000U, 3000U, 7000U, 9000U}) {
    const Outcome outcome = run(ken, first_seed);
    successes += outcome.successes;
    flips += outcome.flips;
  }
  std::printf("ken, 200 poses: %d successes, %d flips\n", successes, flips);
  EXPECT_EQ(flips, 0);
  EXPECT_GE(successes, 190);
}

// The free-space term of the verification: the true pose scores better than the ken turned
// end-for-end (pi about its handle, big cup where the small cup is), even after the dense ICP.
TEST(InitialAlignment, VerificationPrefersTheTruePoseOverTheFlip) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  InitialAligner aligner(model);
  const Eigen::Isometry3f flip(Eigen::AngleAxisf(3.14159265F, Eigen::Vector3f::UnitZ()));
  int better = 0;
  constexpr int kSeeds = 20;
  for (int k = 0; k < kSeeds; ++k) {
    const auto seed = 4000U + static_cast<std::uint32_t>(k);
    const Eigen::Isometry3f truth = random_object_pose(seed);
    const Points scene = test::scene_of(ken, model, truth, seed);
    const VerifiedPose right = aligner.verify(scene, truth);
    const VerifiedPose flipped = aligner.verify(scene, truth * flip);
    EXPECT_LT(right.free_space_violations, 0.1F) << "seed " << seed;
    better += right.score_m < flipped.score_m ? 1 : 0;
  }
  EXPECT_EQ(better, kSeeds);
}

// Issue 19, clutter: a hand (a flat face) in front of a third of the ken. The hand's points cost
// the true pose as much as any other, and they pull the refining ICP, so the plain aligner lets
// poses that half-fit the hand win: 0 of 20. The trimmed ICP and the scene term over the best
// 60 % of the points find the ken in 11 of 20. In each of the other 9 the true pose scores
// better than the one chosen, but no hypothesis near it reaches the verification: the LRF
// hypotheses are the limit (docs/matching.md, clutter). Without the hand the trimmed aligner
// finds 18 of 20 against the plain one's 20, which is why trimming is off by default.
TEST(InitialAlignment, TrimmedScoringFindsTheKenHeldInAHandMoreOften) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  InitialAlignmentConfig trimmed_config;
  trimmed_config.trim_factor = 2.5F;
  trimmed_config.score_trim_fraction = 0.6F;
  trimmed_config.score_truncation_m = 0.006F;
  InitialAligner plain(model);
  InitialAligner trimmed(model, trimmed_config);
  int plain_successes = 0;
  int trimmed_successes = 0;
  int trimmed_clean_successes = 0;
  int plain_clean_successes = 0;
  constexpr int kSeeds = 20;
  const auto success = [&](const InitialAlignmentResult& r, const Eigen::Isometry3f& truth) {
    const PoseError e = pose_error(r.T_camera_model, truth, ken.symmetry);
    return r.valid && e.translation_m < 0.005F && e.rotation_deg < 5.0F ? 1 : 0;
  };
  for (int k = 0; k < kSeeds; ++k) {
    const auto seed = 5000U + static_cast<std::uint32_t>(k);
    const Eigen::Isometry3f truth = random_object_pose(seed);
    const Points clean = test::scene_of(ken, model, truth, seed);
    const Points held = test::with_hand(clean, 0.012F, 0.35F);
    plain_successes += success(plain.align(held), truth);
    trimmed_successes += success(trimmed.align(held), truth);
    trimmed_clean_successes += success(trimmed.align(clean), truth);
    plain_clean_successes += success(plain.align(clean), truth);
  }
  std::printf(
      "ken, %d poses: held in a hand plain %d, trimmed %d successes; without the hand plain %d, "
      "trimmed %d\n",
      kSeeds, plain_successes, trimmed_successes, plain_clean_successes, trimmed_clean_successes);
  EXPECT_LE(plain_successes, 2);
  EXPECT_GE(trimmed_successes, 9);
  // On a clean scene trimming is not free (18 of 20 against 20): why it is off by default.
  EXPECT_GE(plain_clean_successes, kSeeds - 1);
  EXPECT_GE(trimmed_clean_successes, kSeeds - 3);
}

TEST(InitialAlignmentLrfs, ModelHasFeatureFramesWithOrthonormalAxes) {
  const ObjectPreset ken = builtin_objects()[0];
  const ModelCloud model = test::model_of(ken);
  const InitialAligner aligner(model);
  ASSERT_GT(aligner.model_lrfs().size(), 10U);
  ASSERT_LT(aligner.model_lrfs().size(), 2 * model.points_m.size());
  for (const auto& lrf : aligner.model_lrfs()) {
    EXPECT_TRUE((lrf.axes.transpose() * lrf.axes).isApprox(Eigen::Matrix3f::Identity(), 1e-4F));
    EXPECT_NEAR(lrf.axes.determinant(), 1.0F, 1e-4F);
  }
}

// Plane hypotheses (our addition beyond the paper's LRF pairs): the model's flat faces.
TEST(InitialAlignmentPlanes, ModelFacesAreTheCylindersCapsAndTheCubesSides) {
  const auto objects = builtin_objects();
  const ModelCloud cylinder = test::model_of(objects[2]);
  const InitialAligner cylinder_aligner(cylinder);
  ASSERT_EQ(cylinder_aligner.model_faces().size(), 2U);
  for (const auto& face : cylinder_aligner.model_faces()) {
    EXPECT_GT(std::abs(face.normal.z()), 0.99F);
    EXPECT_NEAR(std::abs(face.centroid_m.z()), 0.06F, 0.003F);  // the caps at +-height / 2
    EXPECT_LT(face.centroid_m.head<2>().norm(), 0.003F);
  }
  const ModelCloud cube = test::model_of(objects[1]);
  const InitialAligner cube_aligner(cube);
  EXPECT_EQ(cube_aligner.model_faces().size(), 6U);
}

// The cylinder seen end-on shows a flat disc: no model LRF lies on the flat cap, so only the
// plane hypotheses propose the right pose (SimAccuracy.CylinderOnRefinedDepth's start pose).
TEST(InitialAlignmentPlanes, CylinderSeenEndOnIsAligned) {
  const ObjectPreset object = builtin_objects()[2];
  const ModelCloud model = test::model_of(object);
  IcpConfig final_config;
  final_config.iterations = {0, 0, 10};
  final_config.metric = IcpMetric::point_to_point;
  Icp icp(model.points_m, final_config, model.normals);
  const auto successes = [&](std::size_t plane_rotations) {
    InitialAlignmentConfig config;
    config.plane_rotations = plane_rotations;
    InitialAligner aligner(model, config);
    int count = 0;
    for (std::uint32_t seed = 0; seed < 10; ++seed) {
      Eigen::Isometry3f truth = Eigen::Isometry3f::Identity();
      // The -z cap faces the camera, tilted by up to 3 degrees, any turn about the axis.
      const float tilt = 0.05F * static_cast<float>(seed % 3) / 2.0F;
      truth.linear() =
          (Eigen::AngleAxisf(tilt, Eigen::Vector3f(1.0F, 0.5F, 0.0F).normalized()) *
           Eigen::AngleAxisf(0.6F * static_cast<float>(seed), Eigen::Vector3f::UnitZ()))
              .toRotationMatrix();
      truth.translation() = Eigen::Vector3f(0.01F, -0.01F, 0.7F);
      const Points scene = test::scene_of(object, model, truth, 100U + seed);
      const InitialAlignmentResult initial = aligner.align(scene);
      if (!initial.valid) continue;
      const IcpResult refined = icp.align(scene, initial.T_camera_model);
      const PoseError error = pose_error(refined.T_camera_model, truth, object.symmetry);
      std::printf("  end-on seed %u (planes %zu, %zu plane hypotheses): %.1f deg %.1f mm\n", seed,
                  initial.scene_planes, initial.plane_hypotheses,
                  static_cast<double>(error.rotation_deg),
                  1e3 * static_cast<double>(error.translation_m));
      if (error.rotation_deg < 5.0F && error.translation_m < 0.005F) ++count;
    }
    return count;
  };
  const int without = successes(0);
  const int with = successes(InitialAlignmentConfig{}.plane_rotations);
  std::printf("cylinder end-on: %d / 10 with plane hypotheses, %d / 10 without\n", with, without);
  EXPECT_EQ(with, 10);
}

TEST(InitialAlignmentLrfs, TooSmallSceneIsInvalid) {
  const ModelCloud model = test::model_of(builtin_objects()[1]);
  InitialAligner aligner(model);
  EXPECT_FALSE(aligner.align(Points{{0.0F, 0.0F, 0.5F}, {0.01F, 0.0F, 0.5F}}).valid);
}

TEST(InitialAlignmentScale, ExtremeModelScalesEndInBoundedWorkOrAClearError) {
  // Issue 20 section 2: the ken's mesh scaled by 1e12-1e30 made the aligner's DistanceGrid spin
  // in the constructor (at load, ignoring SIGTERM). Every scale now either builds (bounded
  // grid) or is refused with a message naming the size; none may hang (the CTest timeout).
  const ObjectPreset ken = builtin_objects()[0];
  for (const float scale : {1e-9F, 1e4F, 1e12F, 1e20F, 1e30F}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    geometry::Mesh mesh = ken.mesh;
    for (auto& v : mesh.vertices) v *= scale;
    ModelCloudConfig config;
    config.target_points = ken.model_points;
    try {
      const ModelCloud model = make_model_cloud(mesh, config);
      const InitialAligner aligner(model);
      EXPECT_LT(scale, 1e6F) << "a model of this size should be refused";
    } catch (const std::invalid_argument& e) {
      EXPECT_GE(scale, 1e6F) << e.what();  // ken is 0.2 m: 1e4 is 2 km, accepted
      EXPECT_NE(std::string(e.what()).find(" m across"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace avs::matching
