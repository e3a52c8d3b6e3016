#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "avs/decode/triangulation.hpp"

namespace avs::decode {
namespace {

geometry::CameraModel distorted_lens() {
  geometry::CameraModel lens = default_sensor_geometry().camera;
  lens.k1 = -0.12;
  lens.k2 = 0.05;
  lens.p1 = 0.001;
  lens.p2 = -0.0015;
  lens.k3 = -0.01;
  return lens;
}

TEST(CameraModel, RayInvertsProjectWithDistortion) {
  const geometry::CameraModel lens = distorted_lens();
  for (int v = 0; v < lens.height; v += 37) {
    for (int u = 0; u < lens.width; u += 41) {
      const Eigen::Vector3d ray = lens.ray(u, v);
      const Eigen::Vector2d uv = lens.project(2.5 * ray);
      EXPECT_NEAR(uv.x(), u, 1e-6);
      EXPECT_NEAR(uv.y(), v, 1e-6);
    }
  }
}

TEST(SensorGeometry, DefaultsFollowThePaper) {
  const SensorGeometry g = default_sensor_geometry();
  EXPECT_NEAR(g.camera.fx_px, 628.8, 0.1);       // 44.3 deg over 512 pixels
  EXPECT_NEAR(g.projector.fx_px, 1094.4, 1e-9);  // throw ratio 1.2 over 912 columns
  EXPECT_EQ(g.layout.first_row, 40);
  EXPECT_EQ(g.layout.used_rows(), 1060);
  EXPECT_TRUE(g.projector_centre_camera_m().isApprox(Eigen::Vector3d(0, 0.2, 0), 1e-12));
  // Optical axes converge at 1 m on the camera axis.
  const Eigen::Vector2d uv =
      g.projector.project(g.R_projector_camera * Eigen::Vector3d(0, 0, 1) + g.t_projector_camera_m);
  EXPECT_NEAR(uv.x(), g.projector.cx_px, 1e-9);
  EXPECT_NEAR(uv.y(), g.projector.cy_px, 1e-9);
}

TEST(SensorGeometry, MatricesOfEq4ProjectLikeTheLensModels) {
  const SensorGeometry g = default_sensor_geometry();
  const Eigen::Vector4d p(0.1, -0.2, 1.3, 1.0);
  const Eigen::Vector3d c = g.camera_matrix() * p;
  const Eigen::Vector3d q = g.projector_matrix() * p;
  const Eigen::Vector2d uv_c = g.camera.project(p.head<3>());
  const Eigen::Vector2d uv_p =
      g.projector.project(g.R_projector_camera * p.head<3>() + g.t_projector_camera_m);
  EXPECT_NEAR(c.x() / c.z(), uv_c.x(), 1e-9);
  EXPECT_NEAR(c.y() / c.z(), uv_c.y(), 1e-9);
  EXPECT_NEAR(q.x() / q.z(), uv_p.x(), 1e-9);
  EXPECT_NEAR(q.y() / q.z(), uv_p.y(), 1e-9);
}

TEST(DepthTable, AgreesWithTheEq4SolveWithoutDistortion) {
  const SensorGeometry g = default_sensor_geometry();
  const DepthTable table(g);
  const ReferenceTriangulator reference(g);
  EXPECT_LT(table.max_plane_fit_error(), 1e-9);
  std::mt19937 random(7);
  std::uniform_int_distribution<int> pixel(0, table.pixel_count() - 1);
  std::uniform_int_distribution<int> code(20, 250);
  for (int trial = 0; trial < 2000; ++trial) {
    const int i = pixel(random);
    const int c = code(random);
    const float z_table = table.depth(i, c);
    const float z_reference = reference.depth(i, c);
    if (!(z_reference > 0.2f && z_reference < 10.0f)) continue;  // working range only
    EXPECT_NEAR(z_table, z_reference, 2e-5 * std::abs(z_reference))
        << "pixel " << i << " code " << c;
  }
  EXPECT_TRUE(std::isnan(table.depth(0, table.invalid_index())));
  EXPECT_TRUE(std::isnan(table.depth(0, g.layout.code_count)));  // unused codes
}

TEST(DepthTable, TriangulatesAPointOnTheCodePlaneWithProjectorDistortion) {
  SensorGeometry g = default_sensor_geometry();
  g.camera = distorted_lens();
  g.projector.k1 = 0.08;
  g.projector.k2 = -0.02;
  const DepthTable table(g);
  EXPECT_GT(table.max_plane_fit_error(), 0.0);
  EXPECT_LT(table.max_plane_fit_error(), 5e-3);  // sine of the worst ray-to-plane angle
  // A point on the ray of projector pixel (column, centre row of code 130) at 1.1 m depth,
  // seen by the camera: the table must give its depth back.
  const int code = 130;
  const Eigen::Vector3d centre = g.projector_centre_camera_m();
  for (int column : {300, 456, 600}) {
    const Eigen::Vector3d d =
        g.R_projector_camera.transpose() * g.projector.ray(column, g.code_centre_row(code));
    const double s = (1.1 - centre.z()) / d.z();
    const Eigen::Vector3d p = centre + s * d;
    const Eigen::Vector2d uv = g.camera.project(p);
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    ASSERT_TRUE(u >= 0 && u < g.camera.width && v >= 0 && v < g.camera.height);
    // Rounding to the pixel centre moves the ray by < 0.5 px; compare at that pixel's own ray.
    const Eigen::Vector3d ray = g.camera.ray(u, v);
    const float z = table.depth(v * g.camera.width + u, code);
    // Depth where the pixel's ray meets the true (curved) row surface, found by bisection on
    // the projected row.
    double lo = 0.5, hi = 2.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      const Eigen::Vector2d q =
          g.projector.project(g.R_projector_camera * (mid * ray) + g.t_projector_camera_m);
      const Eigen::Vector2d q_lo =
          g.projector.project(g.R_projector_camera * (lo * ray) + g.t_projector_camera_m);
      ((q.y() - g.code_centre_row(code)) * (q_lo.y() - g.code_centre_row(code)) > 0 ? lo : hi) =
          mid;
    }
    EXPECT_NEAR(z, 0.5 * (lo + hi), 1e-3) << "column " << column;
  }
}

}  // namespace
}  // namespace avs::decode
