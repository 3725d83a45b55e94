#include "g2p/mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support/gltf_builder.h"

namespace g2p {
namespace {

TEST(Mesh, BoundsAndArea) {
  const Mesh cube = test::box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f});
  const Eigen::AlignedBox3d box = bounds(cube);
  EXPECT_TRUE(box.min().isApprox(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(box.max().isApprox(Eigen::Vector3d::Ones()));
  EXPECT_DOUBLE_EQ(surface_area(cube), 6.0);
  EXPECT_DOUBLE_EQ(face_area(cube, 0), 0.5);
  EXPECT_TRUE(bounds(Mesh{}).isEmpty());
}

TEST(Mesh, FaceNormalsPointOutward) {
  const Mesh cube = test::box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f});
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  for (int f = 0; f < cube.num_faces(); ++f) {
    const Eigen::Vector3i& t = cube.triangles[f];
    const Eigen::Vector3d c = (cube.positions[t[0]] + cube.positions[t[1]] + cube.positions[t[2]]).cast<double>() / 3;
    const Eigen::Vector3d n = face_normal(cube, f);
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    EXPECT_GT(n.dot(c - centre), 0.0) << "face " << f;
  }
}

TEST(Mesh, VertexNormalsOfACubeCornerAreDiagonal) {
  Mesh cube = test::box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f});
  compute_vertex_normals(cube);
  ASSERT_EQ(cube.normals.size(), cube.positions.size());
  for (int v = 0; v < cube.num_vertices(); ++v) {
    // Each corner touches three faces with equal angle weight: normal along the diagonal.
    const Eigen::Vector3f expected = (cube.positions[v] - Eigen::Vector3f::Constant(0.5f)).normalized();
    EXPECT_TRUE(cube.normals[v].isApprox(expected, 1e-5f)) << "vertex " << v << ": " << cube.normals[v].transpose();
  }
}

TEST(Mesh, FlagsRepeatedAndCollinearFacesAsDegenerate) {
  Mesh m = test::box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f});
  m.positions.push_back({2.f, 0.f, 0.f});
  m.positions.push_back({3.f, 0.f, 0.f});
  m.triangles.emplace_back(1, 8, 9);  // collinear along x
  m.triangles.emplace_back(2, 2, 3);  // repeated index
  EXPECT_EQ(flag_degenerate_faces(m), 2);
  ASSERT_EQ(m.face_flags.size(), m.triangles.size());
  EXPECT_TRUE(m.is_degenerate(12));
  EXPECT_TRUE(m.is_degenerate(13));
  for (int f = 0; f < 12; ++f) EXPECT_FALSE(m.is_degenerate(f));
  EXPECT_EQ(face_normal(m, 12), Eigen::Vector3d::Zero());
}

TEST(Mesh, ValidateNamesTheOffendingElement) {
  Mesh m = test::box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f});
  EXPECT_TRUE(validate(m).ok());

  Mesh bad_index = m;
  bad_index.triangles[5][1] = 8;
  Status s = validate(bad_index);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "face 5: index 8 out of range (8 vertices)");

  Mesh bad_vertex = m;
  bad_vertex.positions[3].y() = std::nanf("");
  EXPECT_EQ(validate(bad_vertex).message(), "vertex 3 has a non-finite coordinate");

  Mesh bad_sizes = m;
  bad_sizes.face_source.resize(3);
  EXPECT_EQ(validate(bad_sizes).message(), "face_source has 3 entries, expected 12 (one per triangle)");
}

}  // namespace
}  // namespace g2p
