// Mesh loaders: round trips through every writer, hand-written files of each format, and
// errors that name the file and line.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "avs/geometry/mesh.hpp"
#include "avs/geometry/primitives.hpp"
#include "avs/testing/scratch_dir.hpp"

namespace avs::geometry {
namespace {

class MeshIoTest : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const {
    static const avs::testing::ScratchDir dir("avs_mesh_io_");
    return (dir / name).string();
  }
  std::string write(const std::string& name, const std::string& text) const {
    const std::string p = path(name);
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  static void expect_same(const Mesh& a, const Mesh& b) {
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
      EXPECT_TRUE(a.vertices[i].isApprox(b.vertices[i], 1e-6f)) << "vertex " << i;
    }
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
      EXPECT_EQ(a.triangles[i], b.triangles[i]) << "triangle " << i;
    }
  }
  /// STL does not keep vertex order: compare the triangles' corner positions instead.
  static void expect_same_triangles(const Mesh& a, const Mesh& b) {
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    for (std::size_t i = 0; i < a.triangles.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(a.vertices[a.triangles[i][c]].isApprox(b.vertices[b.triangles[i][c]], 1e-6f))
            << "triangle " << i << " corner " << c;
      }
    }
  }
  static std::string error_of(const std::string& p) {
    try {
      load_mesh(p);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "no error";
  }
};

TEST_F(MeshIoTest, BinaryPlyRoundTrip) {
  const Mesh mesh = make_cylinder(0.04, 0.12, 16);
  save_ply(mesh, path("c.ply"));
  expect_same(mesh, load_mesh(path("c.ply")));
}

TEST_F(MeshIoTest, StlRoundTripBinaryAndAscii) {
  const Mesh mesh = make_box(Eigen::Vector3d(0.1, 0.2, 0.3));  // corners shared: merged again
  save_stl(mesh, path("b.stl"), true);
  expect_same_triangles(mesh, load_mesh(path("b.stl")));
  save_stl(mesh, path("a.stl"), false);
  expect_same_triangles(mesh, load_mesh(path("a.stl")));
}

TEST_F(MeshIoTest, ObjRoundTrip) {
  const Mesh mesh = make_plane(1.0, 2.0, 3);
  save_obj(mesh, path("p.obj"));
  expect_same(mesh, load_mesh(path("p.obj")));
}

TEST_F(MeshIoTest, AsciiPlyWithExtraPropertiesAndQuads) {
  const std::string p = write("q.ply",
                              "ply\nformat ascii 1.0\ncomment quad\nelement vertex 4\n"
                              "property double x\nproperty double y\nproperty double z\n"
                              "property uchar red\nelement face 1\n"
                              "property list uchar uint vertex_index\nend_header\n"
                              "0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 9\n4 0 1 2 3\n");
  const Mesh mesh = load_mesh(p);
  ASSERT_EQ(mesh.vertices.size(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 2u);  // fan
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_FLOAT_EQ(mesh.vertices[2].y(), 1.0f);
}

TEST_F(MeshIoTest, ObjFaceFormatsAndNegativeIndices) {
  const std::string p = write("f.obj",
                              "# test\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                              "f 1/1/1 2/1/1 3/1/1\nf -4//1 -2//1 -1//1\n");
  const Mesh mesh = load_mesh(p);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
}

TEST_F(MeshIoTest, ErrorsNameFileAndLine) {
  EXPECT_NE(error_of(path("missing.ply")).find("missing.ply: cannot open"), std::string::npos);
  EXPECT_NE(error_of(write("x.dae", "")).find("unknown mesh extension 'dae'"), std::string::npos);
  const std::string bad_header =
      write("h.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\n");
  EXPECT_NE(error_of(bad_header).find("h.ply:4: unknown property type 'flot'"), std::string::npos)
      << error_of(bad_header);
  const std::string bad_body = write("b.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                     "property float y\nproperty float z\nend_header\n0 zero 0\n");
  EXPECT_NE(error_of(bad_body).find("b.ply:8: expected a number"), std::string::npos)
      << error_of(bad_body);
  const std::string bad_index = write("i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n");
  EXPECT_NE(error_of(bad_index).find("i.obj:5: face index 7 out of range"), std::string::npos)
      << error_of(bad_index);
  const std::string big_endian = write("e.ply", "ply\nformat binary_big_endian 1.0\nend_header\n");
  EXPECT_NE(error_of(big_endian).find("e.ply:2: unsupported PLY format"), std::string::npos);
  const std::string bad_stl =
      write("s.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n");
  EXPECT_NE(error_of(bad_stl).find("s.stl:4: expected three numbers"), std::string::npos)
      << error_of(bad_stl);
}

TEST_F(MeshIoTest, TruncatedBinaryPlyAndBadIndicesAreReported) {
  const Mesh mesh = make_box(Eigen::Vector3d::Constant(1.0));
  save_ply(mesh, path("t.ply"));
  std::filesystem::resize_file(path("t.ply"), std::filesystem::file_size(path("t.ply")) - 5);
  EXPECT_NE(error_of(path("t.ply")).find("binary body ends inside element 'face'"),
            std::string::npos);
  Mesh broken = mesh;
  broken.triangles[3][1] = 99;
  save_ply(broken, path("bad.ply"));
  EXPECT_NE(error_of(path("bad.ply")).find("triangle 3 uses vertex 99"), std::string::npos);
}

// Found by tests/fuzz (fuzz_ply_mesh): a float list length of 2.96e29 was cast to an integer
// (undefined behaviour); lengths and indices must be whole numbers in range.
TEST_F(MeshIoTest, PlyListLengthsAndIndicesMustBeWholeNumbersInRange) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list float int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_NE(error_of(write("l.ply", header + "2.96e29 0 1 2\n"))
                .find("l.ply:13: list length 2.96e+29 is not a whole number"),
            std::string::npos)
      << error_of(path("l.ply"));
  EXPECT_NE(error_of(write("f.ply", header + "3.5 0 1 2\n"))
                .find("f.ply:13: list length 3.5 is not a whole number"),
            std::string::npos)
      << error_of(path("f.ply"));
  EXPECT_NE(error_of(write("n.ply", header + "3 0 1 1e12\n")).find("n.ply:13: list item 1e+12"),
            std::string::npos)
      << error_of(path("n.ply"));
}

// tests/fuzz found a vertex element with a list property before x, y, z read its coordinates
// one place off and past the item's values (ASan: heap-buffer-overflow in add_item).
TEST_F(MeshIoTest, PlyVertexWithAListPropertyBeforeItsCoordinatesReadsThemRight) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty list uchar int extra\n"
      "property float x\nproperty float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const Mesh mesh = load_mesh(write("v.ply", header + "2 7 8 0.5 0 0\n1 9 1 0.25 0\n0 0 1 0.125\n"
                                                      "3 0 1 2\n"));
  ASSERT_EQ(mesh.vertices.size(), 3u);
  EXPECT_EQ(mesh.vertices[0], Eigen::Vector3f(0.5F, 0, 0));
  EXPECT_EQ(mesh.vertices[1], Eigen::Vector3f(1, 0.25F, 0));
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3f(0, 1, 0.125F));
  ASSERT_EQ(mesh.triangles.size(), 1u);
}

}  // namespace
}  // namespace avs::geometry
