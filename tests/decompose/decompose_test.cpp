// The decompose stage: convex hulls within a vertex budget, the voxel-cut
// decomposition on convex and concave parts, fallbacks and option checks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "decompose/decompose_fixtures.h"
#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "support/gltf_builder.h"

namespace g2p {
namespace {

std::vector<Eigen::Vector3d> sphere_points(int n, double radius, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss;
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d v(gauss(rng), gauss(rng), gauss(rng));
    p.push_back(radius * v.normalized());
  }
  return p;
}

// Every hull closed, outward and convex: all vertices behind every face.
void expect_convex(const Mesh& hull) {
  const MeshChecks checks = check_closed_mesh(hull);
  EXPECT_TRUE(checks.closed);
  EXPECT_TRUE(checks.outward);
  for (int f = 0; f < hull.num_faces(); ++f) {
    const Eigen::Vector3d n = face_normal(hull, f);
    const Eigen::Vector3d a = hull.positions[hull.triangles[f][0]].cast<double>();
    for (const Eigen::Vector3f& p : hull.positions) ASSERT_LE(n.dot(p.cast<double>() - a), 1e-5);
  }
}

ConvexDecomposition run(const Mesh& closed, const std::string& backend, DecomposeOptions options = {}) {
  Result<std::unique_ptr<Decomposer>> d = make_decomposer(backend);
  EXPECT_TRUE(d.ok()) << d.status().to_string();
  Result<ConvexDecomposition> r = decompose_part(closed, **d, options);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? *r : ConvexDecomposition{};
}

TEST(ConvexHull, CubeWithInteriorPoints) {
  std::vector<Eigen::Vector3d> p;
  for (int c = 0; c < 8; ++c) p.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  for (int i = 0; i < 20; ++i) p.emplace_back(0.1 + 0.04 * i, 0.5, 0.3);
  Result<Mesh> h = convex_hull(p);
  ASSERT_TRUE(h.ok()) << h.status().to_string();
  EXPECT_EQ(h->num_vertices(), 8);
  EXPECT_EQ(h->num_faces(), 12);
  EXPECT_NEAR(enclosed_volume(*h), 1.0, 1e-6);
  expect_convex(*h);
}

TEST(ConvexHull, VertexBudgetKeepsMostOfTheVolume) {
  const std::vector<Eigen::Vector3d> p = sphere_points(2000, 0.1, 7);
  Result<Mesh> full = convex_hull(p);
  ASSERT_TRUE(full.ok());
  EXPECT_GT(full->num_vertices(), 1000);
  for (int budget : {8, 32, 64}) {
    Result<Mesh> h = convex_hull(p, budget);
    ASSERT_TRUE(h.ok()) << h.status().to_string();
    EXPECT_LE(h->num_vertices(), budget);
    EXPECT_GE(h->num_vertices(), budget - 1);
    expect_convex(*h);
    const double ratio = enclosed_volume(*h) / enclosed_volume(*full);
    EXPECT_LE(ratio, 1.0 + 1e-6);
    // A greedy 64-point hull of a sphere keeps most of it; 8 points a third.
    EXPECT_GT(ratio, budget == 8 ? 0.3 : budget == 32 ? 0.75 : 0.85) << budget;
  }
}

TEST(ConvexHull, FlatPointsAreRefused) {
  std::vector<Eigen::Vector3d> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0}};
  Result<Mesh> h = convex_hull(p);
  ASSERT_FALSE(h.ok());
  EXPECT_NE(h.status().message().find("one plane"), std::string::npos) << h.status().to_string();
  EXPECT_FALSE(convex_hull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}).ok());
}

TEST(Decompose, ConvexPartsGetOneHull) {
  const Mesh box = test::box_mesh({0, 0, 0}, {0.3f, 0.1f, 0.05f});
  ConvexDecomposition d = run(box, "voxel-cut");
  ASSERT_EQ(d.hulls.size(), 1u);
  EXPECT_EQ(d.hulls[0].num_vertices(), 8);
  EXPECT_NEAR(d.hulls_volume_m3, d.part_volume_m3, 1e-9);
  EXPECT_FALSE(d.fell_back);
  // Half a cell of the measuring grid at most (0.3 m / 64).
  EXPECT_LE(d.max_distance_m, 0.3 / 64);

  // A sphere of 1280 triangles: convex, one hull within the vertex budget.
  std::vector<std::array<double, 2>> profile;
  for (int i = 0; i <= 20; ++i) {
    const double phi = -std::acos(0.0) + std::acos(-1.0) * i / 20;
    profile.push_back({i == 0 || i == 20 ? 0.0 : 0.2 * std::cos(phi), 0.2 * std::sin(phi)});
  }
  const Mesh sphere = test::revolve(profile, 32);
  d = run(sphere, "voxel-cut");
  ASSERT_EQ(d.hulls.size(), 1u);
  EXPECT_LE(d.hulls[0].num_vertices(), 64);
  expect_convex(d.hulls[0]);
  EXPECT_GT(d.hulls_volume_m3, 0.9 * d.part_volume_m3);
}

TEST(Decompose, UChannelIsCutIntoItsWallsAndBase) {
  const Mesh u = test::u_channel_mesh(0.02f);  // 10 x 6 x 8 cm
  const ConvexDecomposition one = run(u, "hull");
  ASSERT_EQ(one.hulls.size(), 1u);
  EXPECT_GT(one.hulls_volume_m3, 1.5 * one.part_volume_m3);  // the hull fills the channel

  const ConvexDecomposition d = run(u, "voxel-cut");
  EXPECT_GE(d.hulls.size(), 3u);
  EXPECT_LE(d.hulls.size(), 16u);
  for (const Mesh& h : d.hulls) expect_convex(h);
  // Boxes cut from boxes: the hulls tile the channel.
  EXPECT_NEAR(d.hulls_volume_m3, d.part_volume_m3, 0.02 * d.part_volume_m3);
  EXPECT_LT(d.max_distance_m, 0.2 * one.max_distance_m);
  EXPECT_LT(d.max_distance_m, 0.005);
}

TEST(Decompose, BowlKeepsItsHollow) {
  const Mesh bowl = test::bowl_mesh(0.1, 0.012);
  ASSERT_TRUE(check_closed_mesh(bowl).watertight());
  const ConvexDecomposition one = run(bowl, "hull");
  const ConvexDecomposition d = run(bowl, "voxel-cut");
  EXPECT_GT(one.hulls_volume_m3, 2.5 * one.part_volume_m3);  // a hemisphere against its 12 mm shell
  EXPECT_GT(d.hulls.size(), 4u);
  EXPECT_LT(d.hulls_volume_m3, 1.6 * d.part_volume_m3);
  EXPECT_LT(d.max_distance_m, 0.3 * one.max_distance_m);
  for (const Mesh& h : d.hulls) {
    expect_convex(h);
    EXPECT_LE(h.num_vertices(), 64);
  }
  // Nothing fills the bowl's middle: the point 2 cm above the inner bottom
  // is outside every hull.
  const Eigen::Vector3d probe(0, 0, 0.1 - 0.088 + 0.02);
  for (const Mesh& h : d.hulls) {
    bool inside = true;
    for (int f = 0; f < h.num_faces() && inside; ++f)
      inside = face_normal(h, f).dot(probe - h.positions[h.triangles[f][0]].cast<double>()) < 0;
    EXPECT_FALSE(inside);
  }
}

TEST(Decompose, HacdWhenBuiltWithIt) {
  if (!decomposer_registry().contains("hacd")) GTEST_SKIP() << "built without libbullet-extras-dev";
  const Mesh bowl = test::bowl_mesh(0.1, 0.012);
  const ConvexDecomposition one = run(bowl, "hull");
  DecomposeOptions options;
  options.max_hulls = 12;
  const ConvexDecomposition d = run(bowl, "hacd", options);
  EXPECT_FALSE(d.fell_back);
  EXPECT_GT(d.hulls.size(), 1u);
  EXPECT_LE(d.hulls.size(), 12u);
  for (const Mesh& h : d.hulls) expect_convex(h);
  EXPECT_LT(d.hulls_volume_m3, 0.9 * one.hulls_volume_m3);  // it does carve the hollow
  EXPECT_LT(d.max_distance_m, 0.5 * one.max_distance_m);
  // The hulls lie where the bowl is: HACD's normalisation is undone.
  Eigen::AlignedBox3d box;
  for (const Mesh& h : d.hulls) box.extend(bounds(h));
  EXPECT_LT((box.min() - bounds(bowl).min()).norm(), 0.01);
  EXPECT_LT((box.max() - bounds(bowl).max()).norm(), 0.01);
  EXPECT_FALSE(make_decomposer("hacd", {{"triangles", "5"}}).ok());
}

TEST(Decompose, BudgetsAreHonoured) {
  const Mesh bowl = test::bowl_mesh(0.1, 0.012);
  DecomposeOptions options;
  options.max_hulls = 3;
  options.max_vertices_per_hull = 8;
  const ConvexDecomposition d = run(bowl, "voxel-cut", options);
  EXPECT_LE(d.hulls.size(), 3u);
  EXPECT_GE(d.hulls.size(), 2u);
  for (const Mesh& h : d.hulls) EXPECT_LE(h.num_vertices(), 8);
  bool noted = false;
  for (const std::string& n : d.notes) noted |= n.find("--max-hulls") != std::string::npos;
  EXPECT_TRUE(noted);
}

class FailingDecomposer : public Decomposer {
 public:
  Status decompose(const Mesh&, const DecomposeOptions&, ConvexDecomposition& out) const override {
    out.hulls.push_back(Mesh{});  // an invalid result is caught as well as an error
    return Status::Ok();
  }
};

TEST(Decompose, AFailingBackendFallsBackToTheSingleHull) {
  const Mesh u = test::u_channel_mesh(0.02f);
  Result<ConvexDecomposition> d = decompose_part(u, FailingDecomposer{});
  ASSERT_TRUE(d.ok()) << d.status().to_string();
  EXPECT_TRUE(d->fell_back);
  EXPECT_EQ(d->backend, "hull");
  ASSERT_EQ(d->hulls.size(), 1u);
  ASSERT_FALSE(d->notes.empty());
  EXPECT_NE(d->notes.back().find("single convex hull"), std::string::npos) << d->notes.back();
}

TEST(Decompose, FlatAndEmptyParts) {
  Mesh square;
  square.positions = {{0, 0, 0}, {0.1f, 0, 0}, {0.1f, 0.1f, 0}, {0, 0.1f, 0}};
  square.triangles = {{0, 1, 2}, {0, 2, 3}};
  const ConvexDecomposition d = run(square, "voxel-cut");
  ASSERT_EQ(d.hulls.size(), 1u);
  expect_convex(d.hulls[0]);
  bool noted = false;
  for (const std::string& n : d.notes) noted |= n.find("flat") != std::string::npos;
  EXPECT_TRUE(noted);

  Mesh line;
  line.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  line.triangles = {{0, 1, 2}};
  Result<std::unique_ptr<Decomposer>> dec = make_decomposer("voxel-cut");
  ASSERT_TRUE(dec.ok());
  Result<ConvexDecomposition> r = decompose_part(line, **dec);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("no convex hull"), std::string::npos) << r.status().to_string();
  EXPECT_FALSE(decompose_part(Mesh{}, **dec).ok());
}

TEST(Decompose, OptionsAndSettingsAreChecked) {
  DecomposeOptions o;
  o.max_hulls = 0;
  EXPECT_NE(validate(o).message().find("--max-hulls"), std::string::npos);
  o = {};
  o.max_vertices_per_hull = 300;
  EXPECT_NE(validate(o).message().find("--hull-vertices"), std::string::npos);
  EXPECT_TRUE(validate(DecomposeOptions{}).ok());

  EXPECT_TRUE(decomposer_registry().contains("voxel-cut"));
  EXPECT_TRUE(decomposer_registry().contains("hull"));
  EXPECT_FALSE(make_decomposer("vhacd").ok());
  Result<std::unique_ptr<Decomposer>> bad = make_decomposer("voxel-cut", {{"resolution", "4"}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("resolution"), std::string::npos);
  EXPECT_TRUE(make_decomposer("voxel-cut", {{"resolution", "32"}, {"error", "0.05"}, {"cuts", "6"}}).ok());
  EXPECT_FALSE(make_decomposer("hull", {{"resolution", "32"}}).ok());
}

}  // namespace
}  // namespace g2p
