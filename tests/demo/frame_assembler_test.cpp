// FrameAssembler: one report row per depth update, assembled from pieces that arrive in any
// order within a step, matched with the ground truth of the same stamp.
#include "avs/run_recorder/frame_assembler.hpp"

#include <gtest/gtest.h>

namespace avs::run_recorder {
namespace {

constexpr std::int64_t kMs = 1'000'000;

/// The paper's camera (512 x 512, f = 628.8 px, principal point at the centre).
geometry::CameraModel paper_camera() {
  return {
      .width = 512, .height = 512, .fx_px = 628.8, .fy_px = 628.8, .cx_px = 255.5, .cy_px = 255.5};
}

Truth truth_at(double x) {
  Truth t;
  t.world.p_world_m = {x, 0, 0};
  t.p_camera_m = {0, 0, 1.0};  // on the optical axis: in view
  t.pan_rad = x;
  return t;
}

TEST(FrameAssembler, OneRowPerDepthUpdateWithTheTruthOfItsStamp) {
  std::vector<report::FrameRow> rows;
  FrameAssembler a([&](const report::FrameRow& r) { rows.push_back(r); });
  a.set_camera(paper_camera());
  for (int frame = 1; frame <= 10; ++frame) {
    const std::int64_t stamp = frame * kMs;
    a.on_truth(stamp, truth_at(frame));
    if (frame % 2 != 0) continue;  // a depth update every second frame (500 Hz)
    // The pieces of one update in an arbitrary order, the depth image not first.
    a.on_timing(stamp, "decode", 0.2);
    a.on_target(stamp, true, 255.5 + frame, 255.5 - frame);
    a.on_depth(stamp);
    a.on_timing(stamp, "tracking", 0.01);
    a.on_match(stamp, report::MatchState::tracking, 120, 0.05);
    report::Pose meas = truth_at(frame).world;
    meas.p_world_m.x() += 0.001;
    a.on_pose_world(stamp, meas);
  }
  EXPECT_EQ(rows.size(), 3u);  // the newest two wait for later pieces
  a.flush();
  ASSERT_EQ(rows.size(), 5u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int frame = 2 * static_cast<int>(i + 1);
    const auto& r = rows[i];
    EXPECT_DOUBLE_EQ(r.t_s, frame * 1e-3);
    EXPECT_DOUBLE_EQ(r.truth.p_world_m.x(), frame);  // not a neighbouring frame's truth
    EXPECT_DOUBLE_EQ(r.pan_rad, frame);
    EXPECT_TRUE(r.in_view);
    ASSERT_TRUE(r.centroid_px.has_value());
    EXPECT_DOUBLE_EQ(r.centroid_px->x(), frame);  // relative to the principal point
    EXPECT_DOUBLE_EQ(r.centroid_px->y(), -frame);
    ASSERT_TRUE(r.meas.has_value());
    EXPECT_NEAR(r.meas->p_world_m.x() - r.truth.p_world_m.x(), 0.001, 1e-12);
    EXPECT_EQ(r.scene_points, 120);
    EXPECT_EQ(r.decode_ms.value_or(-1), 0.2);
    EXPECT_EQ(r.tracking_ms.value_or(-1), 0.01);
    EXPECT_EQ(r.matching_ms.value_or(-1), 0.05);
  }
  EXPECT_EQ(a.stats().poses, 5u);
  EXPECT_EQ(a.stats().rows_without_truth, 0u);
}

TEST(FrameAssembler, NoPoseWithoutAMatchStateThatHasOneAndNoRowWithoutTruth) {
  std::vector<report::FrameRow> rows;
  FrameAssembler a([&](const report::FrameRow& r) { rows.push_back(r); });
  a.set_camera(paper_camera());
  a.on_truth(2 * kMs, truth_at(2));
  a.on_depth(2 * kMs);
  a.on_match(2 * kMs, report::MatchState::lost, 10, 0.1);
  a.on_pose_world(2 * kMs, truth_at(2).world);
  a.on_depth(4 * kMs);  // no truth for this stamp
  a.flush();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_FALSE(rows[0].meas.has_value());
  EXPECT_EQ(rows[0].match_state, report::MatchState::lost);
  EXPECT_FALSE(rows[0].centroid_px.has_value());
  EXPECT_EQ(a.stats().rows_without_truth, 1u);
}

TEST(FrameAssembler, TargetBehindOrOutsideTheImageIsNotInView) {
  const geometry::CameraModel camera = paper_camera();
  EXPECT_TRUE(in_view(camera, {0, 0, 1}));
  EXPECT_FALSE(in_view(camera, {0, 0, -1}));
  EXPECT_FALSE(in_view(camera, {0.5, 0, 1}));  // 314 px right of the centre: outside 512 px
  EXPECT_TRUE(in_view(camera, {0.35, 0, 1}));  // 220 px right: inside
  // Barrel distortion pulls a point near the edge into the image.
  geometry::CameraModel barrel = camera;
  barrel.k1 = -0.3;
  EXPECT_FALSE(in_view(camera, {0.42, 0, 1}));  // 264 px right: just outside the pinhole
  EXPECT_TRUE(in_view(barrel, {0.42, 0, 1}));
}

TEST(FrameAssembler, WithoutACameraModelRowsAreNotInViewAndHaveNoCentroid) {
  std::vector<report::FrameRow> rows;
  FrameAssembler a([&](const report::FrameRow& r) { rows.push_back(r); });
  a.on_truth(2 * kMs, truth_at(2));
  a.on_target(2 * kMs, true, 300, 200);
  a.on_depth(2 * kMs);
  a.flush();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_FALSE(rows[0].in_view);
  EXPECT_FALSE(rows[0].centroid_px.has_value());
}

}  // namespace
}  // namespace avs::run_recorder
