// The depth gate (issue 19, occlusion): an occluder inside Eq. 8's window is left out once the
// target has been seen, the gate follows the target in depth and opens after release_frames.
#include "avs/tracking/depth_gate.hpp"

#include <vector>

#include <gtest/gtest.h>

#include "depth_image.hpp"

namespace avs::tracking {
namespace {

using test::Image;
using test::kCamera;
const MomentsConfig kEq8{0.3, 1.5, 10};

TEST(DepthGate, AnOccluderInFrontIsLeftOutOnceTheTargetIsSeen) {
  DepthGate gate({.half_width_m = 0.2, .release_frames = 3});
  Image target;
  target.fill_rect(30, 20, 6, 6, 1.0F);  // the target, centred at u 32.5, v 22.5
  const auto measure = [&](const Image& image) {
    TargetObservation obs = measure_target(image.view(), kCamera, gate.window(kEq8));
    obs.present = gate.observe(obs);
    return obs;
  };
  EXPECT_FALSE(gate.closed());
  EXPECT_DOUBLE_EQ(measure(target).centroid_u_px, 32.5);
  EXPECT_TRUE(gate.closed());
  EXPECT_DOUBLE_EQ(gate.window(kEq8).depth_min_m, 0.8);
  EXPECT_DOUBLE_EQ(gate.window(kEq8).depth_max_m, 1.2);

  Image occluded = target;
  occluded.fill_rect(2, 2, 10, 40, 0.6F);  // a board 0.6 m away, inside Eq. 8's window
  EXPECT_DOUBLE_EQ(measure(occluded).centroid_u_px, 32.5) << "the board is not target";
  // Without the gate the board pulls the centroid to the left.
  EXPECT_LT(measure_target(occluded.view(), kCamera, kEq8).centroid_u_px, 15.0);

  // The target recedes 5 mm per image: the gate follows it.
  Image receding;
  for (int k = 1; k <= 40; ++k) {
    const float z = 1.0F + 0.005F * static_cast<float>(k);
    receding = Image{};
    receding.fill_rect(30, 20, 6, 6, z);
    const TargetObservation obs = measure(receding);
    ASSERT_TRUE(obs.present) << z;
    EXPECT_NEAR(gate.centre_m(), z, 1e-6);
  }
  EXPECT_NEAR(gate.window(kEq8).depth_max_m, 1.4, 1e-6);
  // A mask half target, half something 0.1 m nearer: the centre moves by max_step_m only.
  Image mixed = receding;
  mixed.fill_rect(30, 20, 3, 6, 1.1F);
  measure(mixed);
  EXPECT_NEAR(gate.centre_m(), 1.19, 1e-6);
  EXPECT_NEAR(gate.window(kEq8).depth_max_m, 1.39, 1e-6);
  EXPECT_DOUBLE_EQ(gate.window({0.3, 1.3, 10}).depth_max_m, 1.3) << "never beyond phi_h";

  // Hidden entirely (only the board): closed for release_frames, then Eq. 8's window again.
  Image board_only;
  board_only.fill_rect(2, 2, 10, 40, 0.6F);
  EXPECT_FALSE(measure(board_only).present);
  EXPECT_FALSE(measure(board_only).present);
  EXPECT_TRUE(gate.closed());
  EXPECT_FALSE(measure(board_only).present);
  EXPECT_FALSE(gate.closed()) << "released after 3 frames";
  EXPECT_TRUE(measure(board_only).present) << "now the board is the target, at its depth";
  EXPECT_NEAR(gate.centre_m(), 0.6, 1e-6);
}

// The rolling decoder's wrong depths along a passing board's fast edges land anywhere between
// the board and the wall, some at the target's depth: only those near the last target count.
TEST(DepthGate, WrongDepthsFarFromTheTargetAreLeftOutByTheRegion) {
  DepthGate gate({.half_width_m = 0.2, .release_frames = 3});
  Image target;
  target.fill_rect(40, 20, 6, 6, 1.0F);  // u 40..45, v 20..25
  EXPECT_TRUE(gate.observe(measure_target(target.view(), kCamera, gate.window(kEq8))));
  const MomentsConfig window = gate.window(kEq8);
  // Centroid u 42.5 +- (1.5 x sqrt(36) + 20 = 29 px).
  EXPECT_EQ(window.region.u_min, 13);
  EXPECT_EQ(window.region.u_max, 72);
  Image streak = target;
  streak.fill_rect(2, 5, 4, 30, 1.05F);  // wrong depths at the target's depth, far left
  const TargetObservation obs = measure_target(streak.view(), kCamera, window);
  EXPECT_DOUBLE_EQ(obs.m00, 36);
  EXPECT_DOUBLE_EQ(obs.centroid_u_px, 42.5);
  // Eq. 8's window alone takes the streak in.
  EXPECT_DOUBLE_EQ(measure_target(streak.view(), kCamera, kEq8).m00, 36 + 120);
}

// The target hidden: what is left in the gate (a few wrong depths) is no target, and does not
// move the gate; the target back whole is.
TEST(DepthGate, ARemnantOfAHiddenTargetIsNoTarget) {
  DepthGate gate({.half_width_m = 0.2, .release_frames = 100});
  Image target;
  target.fill_rect(30, 20, 10, 10, 1.0F);  // 100 px
  EXPECT_TRUE(gate.observe(measure_target(target.view(), kCamera, gate.window(kEq8))));
  Image remnant;
  remnant.fill_rect(30, 20, 5, 8, 0.9F);  // 40 px, 0.1 m nearer: below 50 % of 100
  const TargetObservation obs =
      measure_target(remnant.view(), kCamera, gate.window({0.3, 1.5, 10}));
  ASSERT_TRUE(obs.present) << "Eq. 8 and min_area_px alone take it";
  EXPECT_FALSE(gate.observe(obs));
  EXPECT_DOUBLE_EQ(gate.centre_m(), 1.0) << "the gate did not move";
  EXPECT_TRUE(gate.observe(measure_target(target.view(), kCamera, gate.window(kEq8))));
}

TEST(DepthGate, OffIsEq8sWindow) {
  DepthGate gate;  // half_width_m 0
  TargetObservation seen;
  seen.present = true;
  seen.mean_depth_m = 1.0;
  EXPECT_TRUE(gate.observe(seen));
  EXPECT_FALSE(gate.closed());
  EXPECT_DOUBLE_EQ(gate.window(kEq8).depth_min_m, 0.3);
  EXPECT_DOUBLE_EQ(gate.window(kEq8).depth_max_m, 1.5);
  gate.retune({.half_width_m = 0.1});
  EXPECT_TRUE(gate.observe(seen));
  EXPECT_TRUE(gate.closed());
  gate.retune({});
  EXPECT_FALSE(gate.closed()) << "turning it off opens it";
}

}  // namespace
}  // namespace avs::tracking
