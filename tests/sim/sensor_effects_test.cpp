// Sensor effects (issue 19 item 1) against their closed forms: each effect is switched on alone
// on a plane facing the camera, and the rendered image is compared with what the effect's
// formula predicts from the renderer's ground truth (projector row, depth), not from its code.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "avs/geometry/primitives.hpp"
#include "avs/sim/renderer.hpp"
#include "avs/sim/sensor_profile.hpp"
#include "facing_plane.hpp"

namespace avs::sim {
namespace {

using test::facing_plane;

/// A renderer with no noise and no room light, so that each effect is seen alone.
RendererConfig quiet() {
  RendererConfig c;
  c.noise_sigma_dn = 0;
  c.ambient_level = 0;
  return c;
}

double normal_cdf(double z) {
  return 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

struct Stats {
  double mean = 0, variance = 0;
  long count = 0;
};
/// Mean and variance over the centre 200 x 200 pixels of `f(i)`.
template <typename F>
Stats centre_stats(const MonoImage& image, F f) {
  Stats s;
  double sum = 0, sum2 = 0;
  for (int y = image.height / 2 - 100; y < image.height / 2 + 100; ++y) {
    for (int x = image.width / 2 - 100; x < image.width / 2 + 100; ++x) {
      const double v = f(static_cast<std::size_t>(y) * image.width + x);
      sum += v;
      sum2 += v * v;
      ++s.count;
    }
  }
  s.mean = sum / s.count;
  s.variance = sum2 / s.count - s.mean * s.mean;
  return s;
}

TEST(SensorEffects, DefocusBlursEachStripeEdgeByTheThinLensSigma) {
  RendererConfig config = quiet();
  config.effects.projector.aperture_m = 0.004;
  config.effects.projector.focus_distance_m = 1.0;
  config.effects.projector.focused_blur_px = 0.5;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({facing_plane(plane, 0.5)});  // 0.5 m: well in front of the focus
  const decode::SensorGeometry& g = config.geometry;
  const int lsb = g.layout.bit_count - 1;
  MonoImage positive, negative;
  renderer.shade(lsb, true, 1, positive);
  renderer.shade(lsb, false, 2, negative);
  long checked = 0, blurred = 0;
  double worst_dn = 0;
  for (std::size_t i = 0; i < positive.pixels.size(); ++i) {
    const double v = renderer.projector_row()[i];
    const double sum = positive.pixels[i] + negative.pixels[i];  // the whole light (no black)
    if (!std::isfinite(v) || renderer.code()[i] < 0 || sum < 100) continue;
    // Projector depth of the point, from the true depth and the sensor geometry.
    const int x = static_cast<int>(i % positive.width), y = static_cast<int>(i / positive.width);
    const Eigen::Vector3d p = g.camera.ray(x, y) * (renderer.depth_m()[i] / g.camera.ray(x, y).z());
    const double qz = (g.R_projector_camera * p + g.t_projector_camera_m).z();
    const double sigma_px = config.effects.projector.blur_sigma_px(qz, g.projector.fy_px);
    // The LSB's Gray bit flips at odd codes; the distance to the nearest flip, in rows.
    const double code_position = (v + 0.5 - g.layout.first_row) / g.layout.rows_per_code;
    const double t = std::fmod(code_position - 1.0 + 2.0, 2.0);
    const double distance_rows = std::min(t, 2.0 - t) * g.layout.rows_per_code;
    const int code = renderer.code()[i];
    const int bit = static_cast<int>(decode::binary_to_gray(static_cast<std::uint32_t>(code)) & 1u);
    const double same_side = normal_cdf(distance_rows / sigma_px);
    const double expected = sum * (bit ? same_side : 1 - same_side);
    worst_dn = std::max(worst_dn, std::abs(positive.pixels[i] - expected));
    ++checked;
    if (same_side < 0.9) ++blurred;
  }
  EXPECT_GT(checked, 100000);
  // A visible blur: at 0.5 m sigma is about 1.2 DMD rows, so a good share of pixels sit
  // within a sigma of an LSB edge (4 rows per code).
  EXPECT_GT(blurred, checked / 20) << "defocus not rendered";
  EXPECT_LE(worst_dn, 1.6) << "rounding of the two frames and the CDF table allow 1.6 DN";
}

TEST(SensorEffects, BlurSigmaFollowsTheThinLens) {
  ProjectorOptics optics;
  optics.aperture_m = 0.004;
  optics.focus_distance_m = 1.0;
  EXPECT_DOUBLE_EQ(optics.blur_sigma_px(1.0, 1000), 0.0);  // in focus
  // At 2 m: disc 4 mm x 1 / 1 = 4 mm; a pixel spans 2 mm: 2 px disc, sigma 0.5 px.
  EXPECT_NEAR(optics.blur_sigma_px(2.0, 1000), 0.5, 1e-12);
  optics.focused_blur_px = 0.5;
  EXPECT_NEAR(optics.blur_sigma_px(2.0, 1000), std::sqrt(0.5), 1e-12);
}

TEST(SensorEffects, CameraDefocusBlursByTheThinLensSigmaAtEachDepth) {
  RendererConfig sharp = quiet();
  RendererConfig defocused = sharp;
  defocused.effects.lens.f_number = 1.4;  // wide open, to see it
  defocused.effects.lens.focus_distance_m = 1.0;
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  const auto render = [&](const RendererConfig& c) {
    Renderer r(c);
    r.set_view({facing_plane(plane, 0.5)});  // well in front of the focus
    MonoImage image;
    r.shade(6, true, 1, image);  // stripes 8 codes wide: edges along the image rows
    return image;
  };
  const MonoImage a = render(sharp), b = render(defocused);
  // The expected blur from the thin lens: (f / N) f |d - focus| / (d (focus - f)) on the sensor.
  const double f = 0.006, fx = sharp.geometry.camera.fx_px;
  const double disc_m = (f / 1.4) * f * 0.5 / (0.5 * (1.0 - f));
  const double sigma = disc_m * fx / f / 4.0;
  EXPECT_NEAR(defocused.effects.lens.blur_sigma_px(0.5, fx), sigma, 1e-12);
  ASSERT_GT(sigma, 0.5);
  // Blur the sharp image with that Gaussian (separable, radius 3, clamped borders) in double.
  const int w = a.width, h = a.height;
  std::vector<double> tmp(a.pixels.size()), expected(a.pixels.size());
  const auto weight = [&](int t) { return std::exp(-0.5 * t * t / (sigma * sigma)); };
  double norm = 0;
  for (int t = -3; t <= 3; ++t) norm += weight(t);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      for (int t = -3; t <= 3; ++t) sum += weight(t) * a.at(std::clamp(x + t, 0, w - 1), y);
      tmp[static_cast<std::size_t>(y) * w + x] = sum / norm;
    }
  }
  double worst = 0, largest_change = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      for (int t = -3; t <= 3; ++t) {
        sum += weight(t) * tmp[static_cast<std::size_t>(std::clamp(y + t, 0, h - 1)) * w + x];
      }
      worst = std::max(worst, std::abs(sum / norm - b.at(x, y)));
      largest_change = std::max(largest_change, std::abs(double(a.at(x, y)) - b.at(x, y)));
    }
  }
  EXPECT_GT(largest_change, 20) << "a visible blur at the stripe edges";
  // The sharp image's rounding, the blurred one's and the 1/16 px sigma levels.
  EXPECT_LE(worst, 1.6);
}

TEST(SensorEffects, BlackLevelLightsTheDarkStripes) {
  RendererConfig config = quiet();
  config.effects.projector.black_level = 0.1;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({facing_plane(plane, 1.0)});
  MonoImage positive, negative;
  renderer.shade(3, true, 1, positive);
  renderer.shade(3, false, 2, negative);
  long dark = 0;
  for (std::size_t i = 0; i < positive.pixels.size(); ++i) {
    const int lo = std::min(positive.pixels[i], negative.pixels[i]);
    const int hi = std::max(positive.pixels[i], negative.pixels[i]);
    if (renderer.code()[i] < 0 || hi < 100) continue;
    // lo = gain x black, hi = gain: the dark stripe carries a tenth of the bright one.
    EXPECT_NEAR(lo, 0.1 * hi, 1.0) << "pixel " << i;
    ++dark;
  }
  EXPECT_GT(dark, 100000);
}

/// Two frames of the projector-off (room light only) image of a plane at 1 m, noise keys 11
/// and 12.
std::pair<MonoImage, MonoImage> two_room_light_frames(const RendererConfig& config) {
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({facing_plane(plane, 1.0, 0.6)});
  std::pair<MonoImage, MonoImage> frames;
  const FramePattern black{ProjectorFrame::kBlack, 0, true};
  renderer.shade(black, 11, frames.first);
  renderer.shade(black, 12, frames.second);
  return frames;
}

TEST(SensorEffects, ShotAndReadNoiseFollowTheSignal) {
  RendererConfig config = quiet();
  config.ambient_level = 0.5;  // flat light, no projector: a uniform 76.5 DN
  config.effects.camera.full_well_e = 12000;
  config.effects.camera.read_noise_e = 25;
  const auto [a, b] = two_room_light_frames(config);
  // The difference of two frames: twice the temporal variance, plus rounding (1/12 each).
  const Stats d = centre_stats(a, [&](std::size_t i) { return double(a.pixels[i]) - b.pixels[i]; });
  const double signal_dn = 255 * 0.6 * 0.5;
  const double e_per_dn = 12000 / 255.0;
  const double expected = signal_dn / e_per_dn + std::pow(25 / e_per_dn, 2) + 1.0 / 12;
  EXPECT_NEAR(d.variance / 2, expected, 0.1 * expected);
  const Stats m = centre_stats(a, [&](std::size_t i) { return double(a.pixels[i]); });
  EXPECT_NEAR(m.mean, signal_dn, 0.2);
}

TEST(SensorEffects, FixedPatternNoiseIsTheSameInEveryFrame) {
  RendererConfig config = quiet();
  config.ambient_level = 0.5;
  config.effects.camera.prnu_fraction = 0.05;
  config.effects.camera.dsnu_dn = 1.0;
  const auto [a, b] = two_room_light_frames(config);
  EXPECT_EQ(a.pixels, b.pixels) << "no temporal noise: only the fixed pattern";
  const Stats s = centre_stats(a, [&](std::size_t i) { return double(a.pixels[i]); });
  const double signal_dn = 255 * 0.6 * 0.5;
  const double expected = std::pow(0.05 * signal_dn, 2) + 1.0 + 1.0 / 12;
  EXPECT_NEAR(s.variance, expected, 0.15 * expected);
  // Another seed, another sensor.
  config.noise_seed = 2;
  EXPECT_NE(a.pixels, two_room_light_frames(config).first.pixels);
}

TEST(SensorEffects, GammaBendsTheResponse) {
  RendererConfig config = quiet();
  config.ambient_level = 0.5;
  config.effects.camera.gamma = 2.2;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({facing_plane(plane, 1.0, 0.6)});
  MonoImage image;
  renderer.shade(FramePattern{ProjectorFrame::kBlack, 0, true}, 1, image);
  const Stats s = centre_stats(image, [&](std::size_t i) { return double(image.pixels[i]); });
  EXPECT_NEAR(s.mean, 255 * std::pow(0.3, 1 / 2.2), 0.6);
}

TEST(SensorEffects, FlickerGainIsTheSineAveragedOverTheExposure) {
  AmbientFlicker flicker;
  flicker.modulation = 0.3;
  flicker.frequency_hz = 100;
  for (const double t : {0.0, 0.0013, 0.0025, 0.0071}) {
    double numeric = 0;
    constexpr int kSteps = 10000;
    for (int k = 0; k < kSteps; ++k) {
      const double s = t - 0.0005 + 0.001 * (k + 0.5) / kSteps;
      numeric += 1 + 0.3 * std::sin(2 * std::numbers::pi * 100 * s);
    }
    EXPECT_NEAR(flicker.mean_gain(t, 0.001), numeric / kSteps, 1e-6) << t;
  }
  EXPECT_EQ(AmbientFlicker{}.mean_gain(0.0025, 0.001), 1.0);
  // The renderer scales the room light (and only it) by the gain.
  RendererConfig config = quiet();
  config.ambient_level = 0.5;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({facing_plane(plane, 1.0, 0.6)});
  MonoImage image;
  renderer.shade(FramePattern{ProjectorFrame::kBlack, 0, true}, 1, image, 1.2f);
  EXPECT_EQ(image.at(256, 256), static_cast<int>(std::lround(255 * 0.3 * 1.2)));
}

TEST(SensorEffects, SpecularLobeBrightensWhereTheHalfVectorMeetsTheNormal) {
  RendererConfig matte = quiet();
  RendererConfig glossy = matte;
  glossy.effects.surface.specular_fraction = 0.3;
  glossy.effects.surface.shininess = 40;
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  const auto whole_light = [&](const RendererConfig& c) {
    Renderer r(c);
    r.set_view({facing_plane(plane, 1.0, 0.6)});
    MonoImage p, n;
    r.shade(0, true, 1, p);
    r.shade(0, false, 2, n);
    std::vector<int> sum(p.pixels.size());
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] = p.pixels[i] + n.pixels[i];
    return sum;
  };
  const std::vector<int> m = whole_light(matte), s = whole_light(glossy);
  // The plane faces the camera; with the projector 0.2 m below, the half vector at the image
  // centre is about 5.7 deg off the normal: (cos 5.7 deg)^40 = 0.82 of the lobe.
  // Expected from the geometry's own projector centre, not the renderer's code.
  const std::size_t centre = 256 * 512 + 256;
  const decode::SensorGeometry& g = matte.geometry;
  const Eigen::Vector3d p = g.camera.ray(256, 256) / g.camera.ray(256, 256).z();  // z = 1 m
  const Eigen::Vector3d h =
      ((g.projector_centre_camera_m() - p).normalized() - p.normalized()).normalized();
  const double n_h = -h.z();  // the plane's normal is -z
  const double cos_theta_light = m[centre] / (255 * 0.6 * 0.8);
  const double expected = m[centre] + 255 * 0.3 * 0.8 * cos_theta_light * std::pow(n_h, 40);
  EXPECT_GT(expected - m[centre], 30) << "a visible lobe";
  EXPECT_NEAR(s[centre], expected, 2.5) << "the two frames' rounding and the matte sum's";
  // Far from the mirror direction (the image's top corner) the lobe is gone.
  EXPECT_NEAR(s[10 * 512 + 10], m[10 * 512 + 10], 2);
}

TEST(SensorEffects, TextureMottlesTheAlbedoOnTheObject) {
  RendererConfig config = quiet();
  config.ambient_level = 0.5;
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  const auto spread = [&](double contrast, double shift_m) {
    RendererConfig c = config;
    c.effects.surface.texture_contrast = contrast;
    Renderer r(c);
    RenderObject o = facing_plane(plane, 1.0, 0.6);
    o.T_camera_object = Eigen::Translation3d(shift_m, 0, 0) * o.T_camera_object;
    r.set_view({o});
    MonoImage image;
    r.shade(FramePattern{ProjectorFrame::kBlack, 0, true}, 1, image);
    return image;
  };
  const MonoImage flat = spread(0, 0), mottled = spread(0.4, 0);
  const Stats f = centre_stats(flat, [&](std::size_t i) { return double(flat.pixels[i]); });
  const Stats t = centre_stats(mottled, [&](std::size_t i) { return double(mottled.pixels[i]); });
  EXPECT_LT(std::sqrt(f.variance), 0.6);
  EXPECT_GT(std::sqrt(t.variance) / t.mean, 0.05);
  // The texture is printed on the object: moving the plane moves its pattern in the image.
  const MonoImage moved = spread(0.4, 0.01);  // 1 cm at 1 m: 6.3 px to the right
  int same = 0, shifted = 0;
  for (int y = 200; y < 300; ++y) {
    for (int x = 200; x < 300; ++x) {
      same += std::abs(mottled.at(x, y) - moved.at(x, y)) <= 1;
      shifted += std::abs(mottled.at(x, y) - moved.at(x + 6, y)) <= 2;
    }
  }
  EXPECT_GT(shifted, 9000);
  EXPECT_LT(same, shifted);
}

TEST(SensorProfile, NamesAndValues) {
  EXPECT_EQ(parse_sensor_profile("ideal"), SensorProfile::kIdeal);
  EXPECT_EQ(parse_sensor_profile("realistic"), SensorProfile::kRealistic);
  try {
    parse_sensor_profile("real");
    FAIL() << "accepted an unknown profile";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ideal or realistic"), std::string::npos);
  }
  SimulatorConfig c;
  apply_sensor_profile(SensorProfile::kRealistic, c);
  EXPECT_TRUE(c.renderer.effects.changes_pattern_light());
  EXPECT_FALSE(c.renderer.effects.camera.is_ideal());
  EXPECT_TRUE(c.renderer.effects.lens.blurs());
  EXPECT_GT(c.motion_blur_samples, 1);
  EXPECT_EQ(c.renderer.effects.problem(), "");
  apply_sensor_profile(SensorProfile::kIdeal, c);
  const SimulatorConfig defaults;
  EXPECT_FALSE(c.renderer.effects.changes_pattern_light());
  EXPECT_TRUE(c.renderer.effects.camera.is_ideal());
  EXPECT_FALSE(c.renderer.effects.lens.blurs());
  EXPECT_EQ(c.motion_blur_samples, defaults.motion_blur_samples);
  EXPECT_EQ(c.renderer.noise_sigma_dn, defaults.renderer.noise_sigma_dn);
}

TEST(SensorProfile, RendererRefusesBadEffectsWithTheReason) {
  RendererConfig c;
  c.effects.camera.gamma = 0;
  try {
    Renderer r(c);
    FAIL() << "accepted gamma 0";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("gamma"), std::string::npos) << e.what();
  }
  RendererConfig calibration;
  calibration.column_layout = decode::CodeLayout{10, 912, 1, 0};
  calibration.effects.projector.aperture_m = 0.004;
  EXPECT_THROW(Renderer r(calibration), std::invalid_argument);
  calibration.effects = {};
  calibration.effects.camera.full_well_e = 12000;  // the camera's effects work everywhere
  EXPECT_NO_THROW(Renderer r(calibration));
}

}  // namespace
}  // namespace avs::sim
