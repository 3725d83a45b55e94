// check_closed_mesh on meshes with known defects.
#include <gtest/gtest.h>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

TEST(MeshChecks, ClosedBoxPasses) {
  const Mesh box = test::box_mesh({0, 0, 0}, {1, 2, 3});
  const MeshChecks c = check_closed_mesh(box, &box);
  EXPECT_TRUE(c.watertight());
  EXPECT_TRUE(c.closed && c.manifold && c.outward && c.self_intersection_free);
  EXPECT_EQ(c.num_components, 1);
  EXPECT_NEAR(c.volume_m3, 6.0, 1e-9);
  EXPECT_NEAR(c.area_m2, 22.0, 1e-6);
  EXPECT_NEAR(c.max_distance_m, 0.0, 1e-9);
}

TEST(MeshChecks, FindsHolesFlipsNonManifoldVerticesAndIntersections) {
  Mesh holed = test::box_mesh({0, 0, 0}, {1, 1, 1});
  holed.triangles.pop_back();
  EXPECT_FALSE(check_closed_mesh(holed).closed);
  EXPECT_FALSE(check_closed_mesh(holed).watertight());

  Mesh inward = test::box_mesh({0, 0, 0}, {1, 1, 1});
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  const MeshChecks flipped = check_closed_mesh(inward);
  EXPECT_TRUE(flipped.closed);
  EXPECT_FALSE(flipped.outward);
  EXPECT_LT(flipped.volume_m3, 0.0);

  // Two boxes sharing only a corner vertex (welded): closed, but that vertex
  // has two separate fans.
  Mesh bowtie = test::box_mesh({0, 0, 0}, {1, 1, 1});
  Mesh other = test::box_mesh({1, 1, 1}, {2, 2, 2});
  const int corner_in_other = 0;  // box_geometry's vertex 0 is the min corner (1, 1, 1)
  ASSERT_EQ(other.positions[corner_in_other], Eigen::Vector3f(1, 1, 1));
  int corner_in_first = -1;
  for (int v = 0; v < bowtie.num_vertices(); ++v)
    if (bowtie.positions[static_cast<std::size_t>(v)] == Eigen::Vector3f(1, 1, 1)) corner_in_first = v;
  ASSERT_GE(corner_in_first, 0);
  const int offset = bowtie.num_vertices();
  test::append_mesh(bowtie, other);
  for (int f = 12; f < bowtie.num_faces(); ++f)
    for (int e = 0; e < 3; ++e)
      if (bowtie.triangles[static_cast<std::size_t>(f)][e] == offset + corner_in_other)
        bowtie.triangles[static_cast<std::size_t>(f)][e] = corner_in_first;
  const MeshChecks bt = check_closed_mesh(bowtie);
  EXPECT_TRUE(bt.closed);
  EXPECT_FALSE(bt.manifold);
  EXPECT_EQ(bt.num_components, 2);

  // Two overlapping boxes: closed and manifold each, but they cut each other.
  Mesh overlap = test::box_mesh({0, 0, 0}, {1, 1, 1});
  test::append_mesh(overlap, test::box_mesh({0.5f, 0.5f, 0.5f}, {1.5f, 1.5f, 1.5f}));
  const MeshChecks ov = check_closed_mesh(overlap);
  EXPECT_TRUE(ov.closed && ov.manifold);
  EXPECT_TRUE(ov.self_intersections_checked);
  EXPECT_FALSE(ov.self_intersection_free);
  EXPECT_GT(ov.num_self_intersections, 0);
  EXPECT_FALSE(ov.watertight());
}

// A surface folded onto itself (the partition completer once simplified a
// sofa's foot into two triangles and their reverses) is closed and manifold
// and encloses a volume of rounding error: not outward, not watertight, as the
// mass properties would refuse it. A thin but real solid still passes.
TEST(MeshChecks, ASurfaceFoldedOntoItselfEnclosesNothing) {
  const auto tetrahedron = [](float height) {
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3f, 0.3f, height}};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    return m;
  };
  const MeshChecks folded = check_closed_mesh(tetrahedron(1e-13f));
  EXPECT_TRUE(folded.closed && folded.manifold);
  EXPECT_GT(folded.volume_m3, 0.0);
  EXPECT_FALSE(folded.outward);
  EXPECT_FALSE(folded.watertight());
  const MeshChecks thin = check_closed_mesh(tetrahedron(1e-4f));  // 0.1 mm over a 1 m base
  EXPECT_TRUE(thin.outward);
  EXPECT_TRUE(thin.watertight());
  EXPECT_NEAR(thin.volume_m3, 1e-4 / 6.0, 1e-9);
}

TEST(MeshChecks, DistanceToThePatch) {
  const Mesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const Mesh far = test::box_mesh({0, 0, 3}, {1, 1, 4});
  const MeshChecks c = check_closed_mesh(far, &box);
  EXPECT_NEAR(c.max_distance_m, 3.0, 1e-6);
  EXPECT_NEAR(c.relative_distance, 3.0 / std::sqrt(3.0), 1e-6);
}

}  // namespace
}  // namespace g2p
