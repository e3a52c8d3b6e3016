// Built-in models: the shipped files match the generator, the ken has its features and
// size, and every model is closed and oriented outwards.
#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "avs/geometry/builtin_models.hpp"
#include "avs/geometry/kendama.hpp"
#include "avs/geometry/primitives.hpp"

namespace avs::geometry {
namespace {

std::string models_dir() {
  const char* root = std::getenv("AVS_SOURCE_DIR");
  return std::string(root ? root : ".") + "/models";
}

/// Signed volume by the divergence theorem: positive when the triangles face outwards.
double signed_volume(const Mesh& m) {
  double v = 0;
  for (const Eigen::Vector3i& t : m.triangles) {
    v += m.vertices[t[0]].cast<double>().dot(
             m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>())) /
         6.0;
  }
  return v;
}

/// Every undirected edge used by exactly two triangles, once in each direction.
bool closed_and_consistent(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const Eigen::Vector3i& t : m.triangles) {
    for (int c = 0; c < 3; ++c) ++directed[{t[c], t[(c + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    if (count != 1) return false;
    const auto reverse = directed.find({edge.second, edge.first});
    if (reverse == directed.end() || reverse->second != 1) return false;
  }
  return true;
}

/// Largest distance from the X axis among vertices with x beyond `x_from` (towards `sign`).
double radius_beyond(const Mesh& m, double x_from, double sign) {
  double r = 0;
  for (const Eigen::Vector3f& v : m.vertices) {
    if (sign * v.x() > sign * x_from) r = std::max(r, std::hypot(double(v.y()), double(v.z())));
  }
  return r;
}

TEST(BuiltinModels, ShippedFilesMatchTheGenerator) {
  for (const std::string& name : builtin_model_names()) {
    const Mesh generated = make_builtin_model(name);
    const Mesh shipped = load_mesh(models_dir() + "/" + name + ".ply");
    ASSERT_EQ(shipped.vertices.size(), generated.vertices.size()) << name;
    ASSERT_EQ(shipped.triangles.size(), generated.triangles.size()) << name;
    for (std::size_t i = 0; i < shipped.vertices.size(); ++i) {
      ASSERT_EQ(shipped.vertices[i], generated.vertices[i]) << name << " vertex " << i;
    }
    for (std::size_t i = 0; i < shipped.triangles.size(); ++i) {
      ASSERT_EQ(shipped.triangles[i], generated.triangles[i]) << name << " triangle " << i;
    }
  }
}

TEST(BuiltinModels, EveryModelIsClosedAndFacesOutwards) {
  for (const std::string& name : builtin_model_names()) {
    const Mesh m = make_builtin_model(name);
    EXPECT_TRUE(closed_and_consistent(m)) << name;
    EXPECT_GT(signed_volume(m), 0) << name;
  }
  EXPECT_NEAR(signed_volume(make_builtin_model("cube")), 1e-3, 1e-9);
  const double cylinder = std::numbers::pi * 0.04 * 0.04 * 0.12;
  EXPECT_NEAR(signed_volume(make_builtin_model("cylinder")), cylinder, 0.01 * cylinder);
}

TEST(BuiltinModels, KenHasItsFeaturesAndSize) {
  const KenDimensions d;
  const Mesh ken = make_ken(d);
  const auto b = bounds(ken);
  EXPECT_NEAR(b(1, 1) - b(1, 0), 0.180, 1e-4);  // spike tip to bottom cup rim along Y
  EXPECT_NEAR(b(1, 1), d.spike_tip_y_m, 1e-6);
  EXPECT_NEAR(b(0, 1), d.big_cup_rim_x_m, 1e-6);    // big cup at +X
  EXPECT_NEAR(b(0, 0), d.small_cup_rim_x_m, 1e-6);  // small cup at -X
  const double big = radius_beyond(ken, 0.03, +1), small = radius_beyond(ken, -0.03, -1);
  EXPECT_NEAR(big, d.big_cup_radius_m, 1e-4);
  EXPECT_NEAR(small, d.small_cup_radius_m, 1e-4);
  EXPECT_GT(big - small, 0.005) << "the small cup must be visibly smaller";
  // Bottom cup: wider than the handle neck, at the -Y end.
  double bottom = 0;
  for (const Eigen::Vector3f& v : ken.vertices) {
    if (v.y() < d.bottom_rim_y_m + 0.004)
      bottom = std::max(bottom, std::hypot(double(v.x()), double(v.z())));
  }
  EXPECT_NEAR(bottom, d.bottom_cup_radius_m, 1e-4);
  EXPECT_GT(bottom, 2 * d.handle_neck_radius_m);
  // Spike: narrows to a point.
  for (const Eigen::Vector3f& v : ken.vertices) {
    if (v.y() > d.spike_tip_y_m - 0.005) {
      EXPECT_LT(std::hypot(v.x(), v.z()), 0.003);
    }
  }
}

TEST(BuiltinModels, UnknownNameThrows) {
  EXPECT_THROW(make_builtin_model("teapot"), std::invalid_argument);
}

}  // namespace
}  // namespace avs::geometry
