// MatchingPipeline: a target cut by the image border gives no pose (the visible part would be
// fitted anywhere) and the tracker starts over; the whole target is matched.
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "avs/matching/border_regions.hpp"
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

// BorderRegions: a board entering from the left edge (0.6 m, a gentle slope) is marked; a
// target in the middle (1.0 m) is kept, also where it touches the board in the image (a 0.4 m
// depth step); pixels outside the depth window are neither.
TEST(BorderRegions, MarksWhatTouchesTheBorderThroughSmoothDepth) {
  constexpr int kW = 64, kH = 48;
  std::vector<float> depth(kW * kH, std::numeric_limits<float>::quiet_NaN());
  int board = 0, target = 0;
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      float& z = depth[static_cast<std::size_t>(v) * kW + u];
      if (u < 20) {
        z = 0.6F + 0.001F * static_cast<float>(u);  // the board, slightly slanted
        ++board;
      } else if (u < 40 && v > 10 && v < 30) {
        z = 1.0F;  // the target, touching the board at u = 20
        ++target;
      } else if (u >= 40) {
        z = 2.0F;  // the wall beyond the depth window
      }
    }
  }
  BorderRegions regions;
  const std::size_t marked = regions.mark({depth.data(), kW, kH, 0}, 0.3F, 1.5F, 0.02F);
  EXPECT_EQ(marked, static_cast<std::size_t>(board));
  const std::uint8_t* keep = regions.keep_mask();
  EXPECT_EQ(keep[5 * kW + 3], 0) << "board";
  EXPECT_EQ(keep[20 * kW + 20], 1) << "target beside the board";
  EXPECT_EQ(keep[20 * kW + 50], 1) << "outside the window: not marked";
  EXPECT_NEAR(regions.depth_separation_m(), 1.0F - 0.61F, 0.011F) << "board 0.6-0.62, target 1.0";
  // A smooth ramp from the board into the target joins them.
  for (int u = 20; u < 30; ++u)
    depth[static_cast<std::size_t>(20) * kW + u] = 0.62F + 0.01F * (u - 20);
  for (int u = 30; u < 40; ++u)
    depth[static_cast<std::size_t>(20) * kW + u] = 0.72F + 0.03F * (u - 30);
  EXPECT_GT(regions.mark({depth.data(), kW, kH, 0}, 0.3F, 1.5F, 0.02F),
            static_cast<std::size_t>(board));
}

TEST(MatchingPipeline, RetuneChangesTheLiveSettingsAndKeepsTheTrackingState) {
  // The matching component's live parameters (issue 18 section 1): the depth window and the
  // per-frame checks change between two frames; the tracker keeps its state.
  const geometry::Mesh cube = make_cube_mesh(0.1F);
  PipelineConfig config;
  config.camera = test::paper_camera();
  MatchingPipeline pipeline(make_model_cloud(cube, ModelCloudConfig{.target_points = 488}), config);
  const DepthImage whole = render_depth(cube, cube_at(0.0F), config.camera);
  PipelineOutput out = pipeline.process(whole.view(), 0.0);
  ASSERT_TRUE(out.has_pose);
  out = pipeline.process(whole.view(), 0.002);
  ASSERT_TRUE(out.has_pose);
  EXPECT_FALSE(out.track.initialised_this_frame) << "tracking, not re-initialising";

  // A window that ends before the cube (about 0.8 m away): no target pixels, no valid match.
  PipelineConfig narrow = config;
  narrow.depth_max_m = 0.5F;
  pipeline.retune(narrow);
  out = pipeline.process(whole.view(), 0.004);
  EXPECT_EQ(out.valid_pixels, 0u);
  EXPECT_FALSE(out.track.pose_valid);  // a failed frame (the tracker coasts until the loss)

  // Back, with an inlier ratio no frame can reach: frames fail until the target is lost
  // after failures_before_loss of them (3), not before.
  PipelineConfig strict = config;
  strict.tracker.min_inlier_ratio = 1.01F;
  strict.tracker.failures_before_loss = 3;
  pipeline.retune(strict);
  EXPECT_EQ(pipeline.config().depth_max_m, config.depth_max_m);
  out = pipeline.process(whole.view(), 0.006);
  EXPECT_GT(out.valid_pixels, 0u);
  EXPECT_FALSE(out.track.pose_valid);

  // Refused, nothing changed: an empty window.
  PipelineConfig empty = config;
  empty.depth_min_m = 1.0F;
  empty.depth_max_m = 0.9F;
  EXPECT_THROW(pipeline.retune(empty), std::invalid_argument);
  EXPECT_EQ(pipeline.config().depth_min_m, config.depth_min_m);
  EXPECT_EQ(pipeline.config().tracker.min_inlier_ratio, 1.01F);

  // The defaults again: tracked poses.
  pipeline.reset();
  pipeline.retune(config);
  out = pipeline.process(whole.view(), 0.008);
  EXPECT_TRUE(out.has_pose);
  EXPECT_LT((out.T_camera_model.translation() - cube_at(0.0F).translation()).norm(), 0.005F);
}

}  // namespace
}  // namespace avs::matching
