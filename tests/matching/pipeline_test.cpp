// MatchingPipeline: a target cut by the image border gives no pose (the visible part would be
// fitted anywhere) and the tracker starts over; the whole target is matched.
#include <gtest/gtest.h>

#include "avs/matching/model_cloud.hpp"
#include "avs/matching/pipeline.hpp"
#include "avs/matching/synthetic.hpp"
#include "scene_fixture.hpp"

namespace avs::matching {
namespace {

Eigen::Isometry3f cube_at(float x_m) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = (Eigen::AngleAxisf(0.5F, Eigen::Vector3f::UnitY()) *
                Eigen::AngleAxisf(0.4F, Eigen::Vector3f::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3f(x_m, 0.0F, 0.8F);
  return T;
}

TEST(MatchingPipeline, TargetCutByTheImageBorderGivesNoPose) {
  const geometry::Mesh cube = make_cube_mesh(0.1F);
  PipelineConfig config;
  config.camera = test::paper_camera();
  MatchingPipeline pipeline(make_model_cloud(cube, ModelCloudConfig{.target_points = 488}), config);

  // Whole, centred: matched.
  const DepthImage whole = render_depth(cube, cube_at(0.0F), config.camera);
  PipelineOutput out = pipeline.process(whole.view(), 0.0);
  EXPECT_FALSE(out.truncated);
  EXPECT_TRUE(out.has_pose);
  EXPECT_LT((out.T_camera_model.translation() - cube_at(0.0F).translation()).norm(), 0.005F);

  // Half out of the image on the right (the image edge is at x = 0.8 m * 256 / 628.8 = 0.33 m).
  const DepthImage cut = render_depth(cube, cube_at(0.33F), config.camera);
  out = pipeline.process(cut.view(), 0.002);
  EXPECT_TRUE(out.truncated);
  EXPECT_GT(out.border_pixels, 20u);
  EXPECT_FALSE(out.has_pose);
  EXPECT_EQ(out.track.state, TrackingState::lost);

  // Whole again: a fresh initial alignment finds it.
  out = pipeline.process(whole.view(), 0.004);
  EXPECT_TRUE(out.has_pose);
  EXPECT_TRUE(out.track.initialised_this_frame);

  // The guard off: the cut view is matched (to whatever fits).
  config.max_border_pixels = -1;
  MatchingPipeline unguarded(make_model_cloud(cube, ModelCloudConfig{.target_points = 488}),
                             config);
  out = unguarded.process(cut.view(), 0.0);
  EXPECT_FALSE(out.truncated);
}

}  // namespace
}  // namespace avs::matching
