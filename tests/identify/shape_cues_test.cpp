// shape_cues() (identify.h): the kind classifier's shape cues on boxes,
// tables and real models, unchanged by size, position and turn about the
// vertical, and empty where a mesh has nothing to measure.
#include <gtest/gtest.h>

#include <cmath>

#include "g2p/identify.h"
#include "g2p/io.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

double cue(const std::vector<double>& cues, const std::string& name) {
  const std::vector<std::string>& names = shape_cue_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return cues.at(i);
  ADD_FAILURE() << "no cue " << name;
  return NAN;
}

// A table in metres, +Z up: a top board on four legs.
Mesh table(float length, float width, float height) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry({0, 0, height - 0.03f}, {length, width, height}, p, t);
  for (float x : {0.02f, length - 0.07f})
    for (float y : {0.02f, width - 0.07f}) test::box_geometry({x, y, 0}, {x + 0.05f, y + 0.05f, height - 0.03f}, p, t);
  return test::mesh_from_geometry(p, t);
}

Mesh transformed(Mesh m, double turn_rad, double scale, const Eigen::Vector3f& shift) {
  const Eigen::Matrix3f r = Eigen::AngleAxisf(static_cast<float>(turn_rad), Eigen::Vector3f::UnitZ()).matrix();
  for (Eigen::Vector3f& v : m.positions) v = static_cast<float>(scale) * (r * v) + shift;
  return m;
}

void expect_same_cues(const std::vector<double>& a, const std::vector<double>& b, double tol, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], tol) << what << ": " << shape_cue_names()[i];
}

}  // namespace

TEST(ShapeCues, ABoxsRatiosAndSymmetry) {
  const std::vector<double> c = shape_cues(test::box_mesh({0, 0, 0}, {2.f, 1.f, 0.5f}));
  ASSERT_EQ(c.size(), shape_cue_names().size());
  EXPECT_NEAR(cue(c, "height_over_long"), std::log(0.25), 1e-6);
  EXPECT_NEAR(cue(c, "short_over_long"), std::log(0.5), 1e-6);
  EXPECT_NEAR(cue(c, "mirror_long"), 1.0, 1e-9);
  EXPECT_NEAR(cue(c, "mirror_short"), 1.0, 1e-9);
  EXPECT_NEAR(cue(c, "area_height"), 0.5, 1e-6);
  // Top and bottom faces: 2 x 2 m^2 of 7 m^2; the sides 3 m^2.
  EXPECT_NEAR(cue(c, "area_level"), 4.0 / 7.0, 1e-6);
  EXPECT_NEAR(cue(c, "area_upright"), 3.0 / 7.0, 1e-6);
  // Seen from above, the bottom and top thirds cover the whole footprint, the middle only its rim.
  EXPECT_NEAR(cue(c, "footprint_low"), 1.0, 1e-9);
  EXPECT_NEAR(cue(c, "footprint_high"), 1.0, 1e-9);
  EXPECT_LT(cue(c, "footprint_middle"), 0.2);
}

TEST(ShapeCues, ATableIsTopHeavyAndOpenBelowAndTurningItChangesNothing) {
  const Mesh t = table(1.6f, 0.8f, 0.75f);
  const std::vector<double> c = shape_cues(t);
  ASSERT_FALSE(c.empty());
  EXPECT_NEAR(cue(c, "height_over_long"), std::log(0.75 / 1.6), 1e-6);
  EXPECT_NEAR(cue(c, "short_over_long"), std::log(0.5), 1e-6);
  EXPECT_GT(cue(c, "footprint_high"), 0.95);  // the top board
  EXPECT_LT(cue(c, "footprint_low"), 0.2);    // four legs
  EXPECT_GT(cue(c, "area_top"), cue(c, "area_bottom"));
  EXPECT_GT(cue(c, "mirror_long"), 0.9);
  // Bigger, elsewhere and turned by 37 degrees: the same cues (the grid's
  // cells fall a little differently on a turned mesh's float coordinates).
  expect_same_cues(c, shape_cues(transformed(t, 37 * M_PI / 180, 3.0, {5, -2, 1})), 0.02, "turned table");
  // An L of two boards is not its own mirror image along its long side.
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> tri;
  test::box_geometry({0, 0, 0}, {2.f, 0.3f, 0.5f}, p, tri);
  test::box_geometry({0, 0.3f, 0}, {0.3f, 1.2f, 0.5f}, p, tri);
  EXPECT_LT(cue(shape_cues(test::mesh_from_geometry(p, tri)), "mirror_long"), 0.6);
}

TEST(ShapeCues, ARealChairTurnedAndScaledKeepsItsCues) {
  const std::string file = test::asset_path("SheenChair");
  G2P_SKIP_WITHOUT(file);
  Result<Model> chair = load_model(file);
  ASSERT_TRUE(chair.ok()) << chair.status().to_string();
  const std::vector<double> c = shape_cues(chair->mesh);
  ASSERT_EQ(c.size(), shape_cue_names().size());
  for (double v : c) EXPECT_TRUE(std::isfinite(v));
  EXPECT_GT(cue(c, "height_over_long"), -0.5);  // about as tall as it is wide
  EXPECT_GT(cue(c, "mirror_short") + cue(c, "mirror_long"), 1.0);
  expect_same_cues(c, shape_cues(transformed(chair->mesh, 1.1, 0.01, {0.3f, 0.2f, 0})), 0.05, "turned chair");
}

TEST(ShapeCues, NothingToMeasureIsEmpty) {
  EXPECT_TRUE(shape_cues(Mesh{}).empty());
  // A flat square has no height to take ratios of.
  std::vector<Eigen::Vector3f> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_TRUE(shape_cues(test::mesh_from_geometry(p, {{0, 1, 2}, {0, 2, 3}})).empty());
  // Degenerate and out-of-range triangles are skipped, not read.
  Mesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  const std::vector<double> box = shape_cues(m);
  m.triangles.push_back({0, 0, 0});
  m.triangles.push_back({0, 1, 99});
  expect_same_cues(box, shape_cues(m), 1e-12, "box with bad triangles");
}

}  // namespace g2p
