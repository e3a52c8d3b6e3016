#include "avs/tracking/tracker.hpp"

#include <gtest/gtest.h>

namespace avs::tracking {
namespace {

TrackerConfig config(IdleBehaviour idle) {
  TrackerConfig c;
  c.law.fx_px = 800;
  c.law.fy_px = 800;
  c.frames_to_track = 3;
  c.frames_to_idle = 2;
  c.idle = idle;
  c.home_q_rad = {0.0, 0.0};
  return c;
}

TargetObservation target(double x_px) {
  TargetObservation o;
  o.present = true;
  o.m00 = 100;
  o.m_g_px = {x_px, 0};
  o.mean_depth_m = 1.0;
  return o;
}

TEST(Tracker, TracksAfterNFramesThenLosesThenIdles) {
  Tracker tracker(config(IdleBehaviour::hold));
  JointState joints;
  EXPECT_EQ(tracker.update(TargetObservation{}, joints).state, TrackingState::idle);
  EXPECT_EQ(tracker.update(target(50), joints).state, TrackingState::idle);
  EXPECT_EQ(tracker.update(target(50), joints).state, TrackingState::idle);
  const TrackerResult r = tracker.update(target(50), joints);
  EXPECT_EQ(r.state, TrackingState::tracking);
  EXPECT_GT(r.torque_nm.x(), 0.0);
  EXPECT_EQ(tracker.update(TargetObservation{}, joints).state, TrackingState::lost);
  EXPECT_EQ(tracker.update(TargetObservation{}, joints).state, TrackingState::lost);
  EXPECT_EQ(tracker.update(TargetObservation{}, joints).state, TrackingState::idle);
}

TEST(Tracker, InterruptedAcquisitionStartsCountingAgain) {
  Tracker tracker(config(IdleBehaviour::hold));
  JointState joints;
  tracker.update(target(10), joints);
  tracker.update(target(10), joints);
  tracker.update(TargetObservation{}, joints);
  tracker.update(target(10), joints);
  EXPECT_EQ(tracker.update(target(10), joints).state, TrackingState::idle);
  EXPECT_EQ(tracker.update(target(10), joints).state, TrackingState::tracking);
}

TEST(Tracker, IdleHoldsTheEntryPoseOrReturnsHome) {
  JointState joints;
  joints.q_rad = {0.3, -0.1};
  Tracker hold(config(IdleBehaviour::hold));
  EXPECT_TRUE(hold.update(TargetObservation{}, joints).torque_nm.isZero());
  joints.q_rad = {0.35, -0.1};  // pushed away: hold pulls back to 0.3
  EXPECT_LT(hold.update(TargetObservation{}, joints).torque_nm.x(), 0.0);

  Tracker home(config(IdleBehaviour::return_home));
  const TrackerResult r = home.update(TargetObservation{}, joints);
  EXPECT_LT(r.torque_nm.x(), 0.0);  // toward q = 0
  EXPECT_GT(r.torque_nm.y(), 0.0);
}

TEST(Tracker, LostHoldsWhereTheTargetWasLost) {
  Tracker tracker(config(IdleBehaviour::return_home));
  JointState joints;
  joints.q_rad = {0.5, 0.0};
  for (int i = 0; i < 3; ++i) tracker.update(target(0), joints);
  ASSERT_EQ(tracker.state(), TrackingState::tracking);
  const TrackerResult lost = tracker.update(TargetObservation{}, joints);
  EXPECT_EQ(lost.state, TrackingState::lost);
  EXPECT_NEAR(lost.torque_nm.x(), 0.0, 1e-12);  // holds 0.5, not home
}

}  // namespace
}  // namespace avs::tracking
