// The Algorithm 1 study (avs code-errors) measures what it says: a still target has no code
// more than one off and nothing for the correction to change; a target moving through the
// stripes has both, and the correction lowers the depth error there (the effect docs/sim.md
// reports, measured by the same function).
#include <gtest/gtest.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/sim/code_error_study.hpp"

namespace avs::sim {
namespace {

CodeErrorStudyConfig swinging_ken(double speed_mps) {
  CodeErrorStudyConfig c;
  SceneObject ken;
  ken.name = "ken";
  ken.mesh = std::make_shared<const geometry::Mesh>(geometry::make_builtin_model("ken"));
  LateralSwingConfig swing;
  swing.axis_world = Eigen::Vector3d::UnitZ();  // across the stripes
  swing.amplitude_m = 0.1;
  swing.peak_speed_mps = speed_mps;
  ken.trajectory = std::make_shared<LateralSwingTrajectory>(swing);
  c.scene.objects.push_back(ken);
  c.scene.objects.push_back(make_background_plane(2.0));
  c.head = at_rest(geometry::look_at(c.simulator.head, swing.T_world_object_centre.translation()));
  c.seconds = 0.2;
  c.decoder.subcode_half_window = 4;
  return c;
}

double mean_off_fraction(const std::vector<CodeErrorSample>& samples) {
  double sum = 0;
  for (const CodeErrorSample& s : samples) sum += s.off_fraction();
  return samples.empty() ? 0 : sum / samples.size();
}

TEST(CodeErrorStudy, StillTargetHasNoCodeErrorsAndNothingToCorrect) {
  const CodeErrorStudy s = run_code_error_study(swinging_ken(0.001));
  ASSERT_EQ(s.corrected.size(), s.uncorrected.size());
  ASSERT_GT(s.corrected.size(), 80u) << "a depth map per pair after the first window";
  EXPECT_GT(s.corrected.front().compared, 2000) << "the ken's coded pixels";
  EXPECT_LT(mean_off_fraction(s.corrected), 0.002);
  EXPECT_LT(mean_off_fraction(s.uncorrected), 0.002);
  long moved = 0;
  for (const long m : s.moved) moved += m;
  EXPECT_LT(moved, 5 * static_cast<long>(s.moved.size()));
}

TEST(CodeErrorStudy, MovingTargetHasCodeErrorsAndTheCorrectionLowersTheirDepthError) {
  const CodeErrorStudy s = run_code_error_study(swinging_ken(1.0));
  ASSERT_FALSE(s.corrected.empty());
  EXPECT_GT(mean_off_fraction(s.uncorrected), 0.02) << "the window mixes old and new bits";
  long moved = 0;
  double rms_with = 0, rms_without = 0;
  for (std::size_t k = 0; k < s.corrected.size(); ++k) {
    moved += s.moved[k];
    rms_with += s.corrected[k].depth_rms_mm;
    rms_without += s.uncorrected[k].depth_rms_mm;
  }
  EXPECT_GT(moved, 20 * static_cast<long>(s.moved.size())) << "the correction changes codes";
  EXPECT_LT(rms_with, rms_without);
  ASSERT_EQ(s.figure_on_object.size(), s.figure_true_code.size());
}

}  // namespace
}  // namespace avs::sim
