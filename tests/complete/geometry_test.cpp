// The complete stage's private geometry: the self-intersection search finds
// what comparing every pair of triangles finds, in the same order at any
// limit.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "complete/complete_fixtures.h"
#include "complete/geometry.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

Mesh cylinder(float radius, float y0, float y1, int segments) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::cylinder_geometry(radius, y0, y1, segments, p, t);
  return test::mesh_from_geometry(p, t);
}

// Every pair (i < j) of triangles that share no vertex and cross, by brute force.
std::vector<std::pair<int, int>> all_crossing_pairs(const Mesh& m) {
  std::vector<std::pair<int, int>> out;
  auto corners = [&](int f, Eigen::Vector3d c[3]) {
    for (int k = 0; k < 3; ++k)
      c[k] = m.positions[static_cast<std::size_t>(m.triangles[static_cast<std::size_t>(f)][k])].cast<double>();
  };
  for (int a = 0; a < m.num_faces(); ++a)
    for (int b = a + 1; b < m.num_faces(); ++b) {
      const Eigen::Vector3i& ta = m.triangles[static_cast<std::size_t>(a)];
      const Eigen::Vector3i& tb = m.triangles[static_cast<std::size_t>(b)];
      bool shared = false;
      for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) shared |= ta[x] == tb[y];
      if (shared) continue;
      Eigen::Vector3d t0[3], t1[3];
      corners(a, t0);
      corners(b, t1);
      if (detail::triangles_intersect(t0, t1)) out.emplace_back(a, b);
    }
  return out;
}

TEST(TriangleBins, FindsEveryCrossingPairAndStopsAtWholeCells) {
  // Two cylinders through each other (one along y, one turned onto x) and a
  // third, apart, that crosses nothing: crossing pairs spread
  // over many cells and waves.
  Mesh mesh = cylinder(0.05f, -0.2f, 0.2f, 512);
  Mesh lying = cylinder(0.03f, -0.2f, 0.2f, 384);
  for (auto& p : lying.positions) p = Eigen::Vector3f(p.y(), p.x(), p.z());
  test::append_mesh(mesh, lying);
  Mesh apart = cylinder(0.02f, -0.1f, 0.1f, 40);
  for (auto& p : apart.positions) p += Eigen::Vector3f(0.5f, 0.0f, 0.0f);
  test::append_mesh(mesh, apart);

  std::vector<std::pair<int, int>> truth = all_crossing_pairs(mesh);
  ASSERT_GT(truth.size(), 100u);
  const detail::TriangleBins bins(mesh, 0.5);  // small cells: the pairs fall in many, over two waves
  std::vector<std::pair<int, int>> all = bins.intersecting_pairs(1 << 30);
  std::vector<std::pair<int, int>> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, truth);  // each pair once, none missed

  // A limit keeps a prefix of the unlimited search: the pairs of whole cells
  // until it is reached, the same on every run.
  for (int limit : {1, 10, 57}) {
    SCOPED_TRACE(limit);
    const std::vector<std::pair<int, int>> some = bins.intersecting_pairs(limit);
    ASSERT_GE(some.size(), static_cast<std::size_t>(limit));
    ASSERT_LT(some.size(), all.size());
    EXPECT_TRUE(std::equal(some.begin(), some.end(), all.begin()));
    EXPECT_EQ(bins.intersecting_pairs(limit), some);
  }

  // The apart cylinder alone: closed, nothing crosses.
  EXPECT_TRUE(detail::TriangleBins(apart).intersecting_pairs(1000).empty());
}

}  // namespace
}  // namespace g2p
