// Renderer against closed-form geometry: a plane at a known distance, an occluding box.
// The expected values come from decode::SensorGeometry's own projection and ray functions
// and analytic intersections, not from the renderer's code paths.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

#include "avs/decode/gray_code.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/sim/renderer.hpp"
#include "facing_plane.hpp"

namespace avs::sim {
namespace {

constexpr double kPlaneDistanceM = 0.9;

/// A large plane facing the camera at z = distance (camera frame).
using test::facing_plane;
RenderObject plane_at(const geometry::Mesh& mesh, double distance_m, double albedo = 0.6) {
  return facing_plane(mesh, distance_m, albedo);
}

/// Slab test: does the segment a -> b cross the axis-aligned box [lo, hi]?
bool segment_hits_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& lo,
                      const Eigen::Vector3d& hi) {
  double t0 = 0, t1 = 1;
  const Eigen::Vector3d d = b - a;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (a[i] < lo[i] || a[i] > hi[i]) return false;
      continue;
    }
    double ta = (lo[i] - a[i]) / d[i], tb = (hi[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

struct Truth {
  Eigen::Vector3d p_camera;
  int row = -1;  ///< projector row of the point (nearest pixel centre)
};

/// Pixel ray meets the plane z = d; its projector row from decode's projection.
Truth analytic_plane_point(const decode::SensorGeometry& g, int x, int y, double d) {
  Truth t;
  t.p_camera = g.camera.ray(x, y) * d;
  const Eigen::Vector3d p_projector = g.R_projector_camera * t.p_camera + g.t_projector_camera_m;
  const Eigen::Vector2d uv = g.projector.project(p_projector);
  if (uv.x() >= -0.5 && uv.x() < g.projector.width - 0.5)
    t.row = static_cast<int>(std::lround(uv.y()));
  return t;
}

/// Renders the plane at kPlaneDistanceM and compares every pixel's bits with the pattern row
/// its ray meets (decode's projection); returns the fraction of bits that agree.
double plane_bit_agreement(const RendererConfig& config, double depth_tolerance_m,
                           const decode::SensorGeometry* truth_geometry = nullptr) {
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({plane_at(plane, kPlaneDistanceM)});
  const decode::SensorGeometry& g = config.geometry;
  const int n = g.layout.bit_count;
  std::vector<MonoImage> positive(n), negative(n);
  for (int k = 0; k < n; ++k) {
    renderer.shade(k, true, frame_noise_key(2 * k), positive[k]);
    renderer.shade(k, false, frame_noise_key(2 * k + 1), negative[k]);
  }
  long lit_pixels = 0, checks = 0, agree = 0;
  for (int y = 0; y < renderer.height(); ++y) {
    for (int x = 0; x < renderer.width(); ++x) {
      const Truth truth =
          analytic_plane_point(truth_geometry ? *truth_geometry : g, x, y, kPlaneDistanceM);
      const std::size_t i = static_cast<std::size_t>(y) * renderer.width() + x;
      EXPECT_NEAR(renderer.depth_m()[i], kPlaneDistanceM, depth_tolerance_m) << x << "," << y;
      if (decode::code_of_row(g.layout, truth.row) < 0) continue;  // not directly lit
      ++lit_pixels;
      for (int k = 0; k < n; ++k) {
        const int difference = positive[k].at(x, y) - negative[k].at(x, y);
        const int measured = difference > 0 ? 1 : 0;
        ++checks;
        agree += measured == decode::pattern_bit(g.layout, truth.row, k) ? 1 : 0;
      }
    }
  }
  EXPECT_GT(lit_pixels, renderer.width() * renderer.height() / 2);
  const double fraction = double(agree) / double(checks);
  std::printf("bit agreement %.5f over %ld lit pixels\n", fraction, lit_pixels);
  return fraction;
}

TEST(Renderer, PlaneBitsMatchProjectorPatternAtTrueSurfacePoint) {
  RendererConfig config;  // paper defaults, noise on
  EXPECT_GE(plane_bit_agreement(config, 1e-4), 0.995);
}

TEST(Renderer, CameraLensDistortionIsRenderedAlongEachPixelsTrueRay) {
  // Another focal length, the principal point off centre, barrel distortion and tangential
  // terms: each camera pixel sees what its undistorted ray meets (bilinear between the ideal
  // pinhole's pixels, so a stripe edge blurs by up to a pixel: a little below the pinhole's).
  RendererConfig config;
  geometry::CameraModel& c = config.geometry.camera;
  c.fx_px = 600.0;
  c.fy_px = 604.0;
  c.cx_px = 262.3;
  c.cy_px = 249.1;
  c.k1 = -0.08;
  c.k2 = 0.02;
  c.p1 = 0.0005;
  c.p2 = -0.0003;
  const double agreement = plane_bit_agreement(config, 1e-4);
  EXPECT_GE(agreement, 0.985);
  // Judged by the pinhole's rays instead, the same frames disagree at the edges of the image:
  // the distortion is really rendered.
  decode::SensorGeometry pinhole = config.geometry;
  pinhole.camera.set_distortion_coefficients({});
  EXPECT_LT(plane_bit_agreement(config, 1e-4, &pinhole), agreement - 0.01);
  const Renderer distorted(config);
  EXPECT_EQ(distorted.width(), 512);
  EXPECT_EQ(distorted.height(), 512);
}

TEST(Renderer, ProjectorLensDistortionIsRenderedAtEachPointsDmdPixel) {
  // Barrel distortion and tangential terms on the projector: each lit point shows the pattern
  // of the DMD pixel whose (distorted) ray meets it, i.e. decode's projector.project().
  RendererConfig config;
  geometry::CameraModel& p = config.geometry.projector;
  p.k1 = -0.06;
  p.k2 = 0.03;
  p.p1 = 0.0008;
  p.p2 = -0.0005;
  const double agreement = plane_bit_agreement(config, 1e-4);
  EXPECT_GE(agreement, 0.99);
  // Judged by the projector's pinhole instead, the same frames disagree: it is really rendered.
  decode::SensorGeometry pinhole = config.geometry;
  pinhole.projector.set_distortion_coefficients({});
  EXPECT_LT(plane_bit_agreement(config, 1e-4, &pinhole), agreement - 0.01);
}

TEST(Renderer, RejectsAProjectorDistortionThatDoesNotInvert) {
  RendererConfig config;
  config.geometry.projector.k1 = -3.0;  // folds back inside the DMD
  EXPECT_THROW(Renderer{config}, std::invalid_argument);
}

class ShadowTest : public ::testing::TestWithParam<double> {};

TEST_P(ShadowTest, ShadowedPixelsShowNoPattern) {
  RendererConfig config;
  config.shadow_map_scale = GetParam();
  Renderer renderer(config);
  const decode::SensorGeometry& g = config.geometry;
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  const Eigen::Vector3d box_size(0.06, 0.06, 0.06), box_centre(0.0, 0.06, 0.5);
  const geometry::Mesh box = geometry::make_box(box_size);
  RenderObject occluder{&box, Eigen::Isometry3d(Eigen::Translation3d(box_centre)), 0.6};
  renderer.set_view({plane_at(plane, kPlaneDistanceM), occluder});
  const Eigen::Vector3d lo = box_centre - box_size / 2, hi = box_centre + box_size / 2;
  const Eigen::Vector3d projector = g.projector_centre_camera_m();

  long shadowed = 0, quiet = 0, lit = 0, patterned = 0;
  std::vector<MonoImage> positive(g.layout.bit_count), negative(g.layout.bit_count);
  for (int k = 0; k < g.layout.bit_count; ++k) {
    renderer.shade(k, true, frame_noise_key(2 * k), positive[k]);
    renderer.shade(k, false, frame_noise_key(2 * k + 1), negative[k]);
  }
  for (int y = 0; y < renderer.height(); ++y) {
    for (int x = 0; x < renderer.width(); ++x) {
      const Truth truth = analytic_plane_point(g, x, y, kPlaneDistanceM);
      if (segment_hits_box(Eigen::Vector3d::Zero(), truth.p_camera, lo, hi)) continue;  // box seen
      if (decode::code_of_row(g.layout, truth.row) < 0) continue;
      // Skip a 4 mm band around the shadow edge, where one pixel spans both sides.
      const Eigen::Vector3d grow(0.002, 0.002, 0.002);
      const bool in_shadow = segment_hits_box(truth.p_camera, projector, lo + grow, hi - grow);
      const bool near_edge = segment_hits_box(truth.p_camera, projector, lo - grow, hi + grow);
      if (!in_shadow && near_edge) continue;
      int max_difference = 0;
      for (int k = 0; k < g.layout.bit_count; ++k) {
        max_difference =
            std::max(max_difference, std::abs(positive[k].at(x, y) - negative[k].at(x, y)));
      }
      if (in_shadow) {
        ++shadowed;
        quiet += max_difference <= 14 ? 1 : 0;  // 14 DN: 5 sigma of the noise difference
        EXPECT_EQ(renderer.code()[static_cast<std::size_t>(y) * renderer.width() + x], -1);
      } else {
        ++lit;
        patterned += max_difference > 50 ? 1 : 0;
      }
    }
  }
  ASSERT_GT(shadowed, 500);
  EXPECT_EQ(quiet, shadowed) << "shadowed pixels with a pattern";
  EXPECT_GE(patterned, lit * 999 / 1000) << "lit pixels without a pattern";
}

INSTANTIATE_TEST_SUITE_P(ShadowMapScales, ShadowTest, ::testing::Values(0.5, 1.0));

TEST(Renderer, IntensityFollowsAlbedoAmbientAndShading) {
  RendererConfig config;
  config.noise_sigma_dn = 0;
  Renderer renderer(config);
  const decode::SensorGeometry& g = config.geometry;
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  // Plane tilted 40 degrees about the camera x axis.
  RenderObject tilted = plane_at(plane, kPlaneDistanceM, 0.5);
  tilted.T_camera_object.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()));
  renderer.set_view({tilted});
  MonoImage image;
  const int x = 256, y = 256;
  const std::size_t i = static_cast<std::size_t>(y) * renderer.width() + x;
  const int code = renderer.code()[i];
  ASSERT_GE(code, 0);
  int k_on = -1;  // a bit that is 1 for this code
  for (int k = 0; k < g.layout.bit_count && k_on < 0; ++k) {
    if (decode::gray_bit(g.layout, static_cast<std::uint32_t>(code), k) == 1) k_on = k;
  }
  ASSERT_GE(k_on, 0);
  renderer.shade(k_on, true, 0, image);
  const Eigen::Vector3d p = g.camera.ray(x, y) * renderer.depth_m()[i];
  const Eigen::Vector3d normal =
      tilted.T_camera_object.linear() * Eigen::Vector3d::UnitZ();  // plane's +Z, now facing us
  const double cos_incidence = normal.dot((g.projector_centre_camera_m() - p).normalized());
  const double expected =
      255 * 0.5 * (config.ambient_level + config.projector_level * cos_incidence);
  EXPECT_NEAR(image.at(x, y), expected, 1.0);
  renderer.shade(k_on, false, 0, image);
  EXPECT_NEAR(image.at(x, y), 255 * 0.5 * config.ambient_level, 1.0);
}

TEST(Renderer, NoiseIsSeededPerFrame) {
  RendererConfig config;
  Renderer renderer(config);
  const geometry::Mesh plane = geometry::make_plane(4.0, 4.0, 1);
  renderer.set_view({plane_at(plane, kPlaneDistanceM)});
  MonoImage a, b, c;
  renderer.shade(3, true, frame_noise_key(7), a);
  renderer.shade(3, true, frame_noise_key(7), b);
  renderer.shade(3, true, frame_noise_key(8), c);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_NE(a.pixels, c.pixels);
  // Noise statistics: difference of two frames has variance 2 sigma^2.
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const double d = double(a.pixels[i]) - double(c.pixels[i]);
    sum += d;
    sum2 += d * d;
  }
  const double mean = sum / a.pixels.size(), var = sum2 / a.pixels.size() - mean * mean;
  EXPECT_NEAR(std::sqrt(var / 2), config.noise_sigma_dn, 0.15);
}

}  // namespace
}  // namespace avs::sim
