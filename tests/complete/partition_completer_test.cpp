// The `partition` completer on shapes with known volumes and on the shared assets.
#include <gtest/gtest.h>

#include <cmath>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "g2p/io.h"
#include "g2p/properties.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

constexpr int kWood = static_cast<int>(PaperClass::kWood);
constexpr int kMetal = static_cast<int>(PaperClass::kMetal);

Completion run_partition(const Mesh& mesh, const std::vector<Part>& parts, const BackendSettings& settings = {}) {
  Result<std::unique_ptr<Completer>> c = make_completer("partition", settings);
  EXPECT_TRUE(c.ok()) << c.status().to_string();
  if (!c.ok()) return {};
  CompletionInput in{&mesh, &parts, &MaterialTable::paper_default()};
  Result<Completion> r = (*c)->complete(in);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? *r : Completion{};
}

void expect_watertight(const CompletedPart& p) {
  EXPECT_TRUE(p.ok) << "part " << p.part;
  EXPECT_TRUE(p.checks.closed) << "part " << p.part;
  EXPECT_TRUE(p.checks.manifold) << "part " << p.part;
  EXPECT_TRUE(p.checks.outward) << "part " << p.part;
  EXPECT_TRUE(p.checks.self_intersections_checked && p.checks.self_intersection_free)
      << "part " << p.part << ": " << p.checks.num_self_intersections << " intersecting pairs";
}

double volume_of(const Mesh& closed) { return solid_mass_properties(closed, 1.0)->volume_m3; }

TEST(PartitionCompleter, ClosedBoxKeepsItsVolume) {
  // Not aligned with the grid: the faces fall between grid points.
  const Mesh box = test::box_mesh({0.013f, -0.21f, 0.1f}, {0.41f, 0.07f, 0.333f});
  const Completion c = run_partition(box, test::single_part(box, kWood));
  ASSERT_EQ(c.parts.size(), 1u);
  expect_watertight(c.parts[0]);
  const double want = volume_of(box);
  EXPECT_NEAR(c.parts[0].checks.volume_m3 / want, 1.0, 0.01);
  EXPECT_NEAR(c.object_volume_m3 / want, 1.0, 0.01);
  EXPECT_EQ(c.parts[0].checks.num_components, 1);
  EXPECT_GT(c.grid_spacing_m, 0.0);
  // The closed surface stays on the box: within a small fraction of a cell.
  EXPECT_LT(c.parts[0].checks.max_distance_m, 0.5 * c.grid_spacing_m);
}

TEST(PartitionCompleter, RotatedBoxAndSphereKeepTheirVolumes) {
  Mesh box = test::box_mesh({-0.2f, -0.1f, -0.05f}, {0.2f, 0.1f, 0.05f});
  const Eigen::Matrix3f r = Eigen::AngleAxisf(0.4f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  for (auto& p : box.positions) p = r * p;
  Completion c = run_partition(box, test::single_part(box, kWood));
  ASSERT_EQ(c.parts.size(), 1u);
  expect_watertight(c.parts[0]);
  EXPECT_NEAR(c.parts[0].checks.volume_m3 / volume_of(box), 1.0, 0.02);

  const Mesh sphere = test::sphere_mesh(0.1, 64);
  c = run_partition(sphere, test::single_part(sphere, kWood));
  ASSERT_EQ(c.parts.size(), 1u);
  expect_watertight(c.parts[0]);
  EXPECT_NEAR(c.parts[0].checks.volume_m3 / volume_of(sphere), 1.0, 0.01);
}

TEST(PartitionCompleter, TwoBoxesOfTwoMaterialsSplitIntoTheirVolumes) {
  // Two closed boxes touching along x = 0.2: their shared faces lie inside
  // the object and must not move the border between the parts.
  Mesh mesh = test::box_mesh({0.0f, 0.0f, 0.0f}, {0.2f, 0.1f, 0.1f});
  const int second = test::append_mesh(mesh, test::box_mesh({0.2f, 0.0f, 0.0f}, {0.3f, 0.1f, 0.1f}));
  std::vector<Part> parts(2);
  parts[0].label = kWood;
  parts[1].label = kMetal;
  for (int f = 0; f < mesh.num_faces(); ++f) parts[f < second ? 0 : 1].faces.push_back(f);
  const Completion c = run_partition(mesh, parts);
  ASSERT_EQ(c.parts.size(), 2u);
  for (const CompletedPart& p : c.parts) expect_watertight(p);
  EXPECT_NEAR(c.parts[0].checks.volume_m3 / 0.002, 1.0, 0.02);
  EXPECT_NEAR(c.parts[1].checks.volume_m3 / 0.001, 1.0, 0.03);
  EXPECT_NEAR(c.parts_volume_m3 / 0.003, 1.0, 0.01);
  EXPECT_NEAR(c.parts_volume_m3 / c.object_volume_m3, 1.0, 0.01);
  // The parts tile the object: their centres of mass sit in their own boxes.
  const MassProperties wood = *solid_mass_properties(c.parts[0].mesh, 1.0);
  const MassProperties metal = *solid_mass_properties(c.parts[1].mesh, 1.0);
  EXPECT_NEAR(wood.center_of_mass.x(), 0.1, 0.005);
  EXPECT_NEAR(metal.center_of_mass.x(), 0.25, 0.005);
}

// A tube open at both ends, along z.
Mesh open_tube(float radius, float length, int segments) {
  Mesh m;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < segments; ++i) {
      const double a = 2 * M_PI * i / segments;
      m.positions.emplace_back(radius * std::cos(a), radius * std::sin(a), ring * length);
    }
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    m.triangles.emplace_back(i, j, segments + j);
    m.triangles.emplace_back(i, segments + j, segments + i);
  }
  return m;
}

TEST(PartitionCompleter, OpenCylinderCloses) {
  const Mesh tube = open_tube(0.05f, 0.2f, 64);
  // Default gap: the outside flows through the open ends, the wall stays a
  // thin closed slab.
  Completion c = run_partition(tube, test::single_part(tube, kWood));
  ASSERT_EQ(c.parts.size(), 1u);
  expect_watertight(c.parts[0]);
  const double full = M_PI * 0.05 * 0.05 * 0.2;
  EXPECT_GT(c.parts[0].checks.volume_m3, 0.0);
  EXPECT_LT(c.parts[0].checks.volume_m3, 0.2 * full);
  // A closing radius wider than the openings seals them: the tube becomes a
  // solid cylinder, less the spherical caps the closing ball leaves at the ends.
  c = run_partition(tube, test::single_part(tube, kWood), {{"resolution", "40"}, {"gap", "16"}});
  ASSERT_EQ(c.parts.size(), 1u);
  expect_watertight(c.parts[0]);
  EXPECT_GT(c.parts[0].checks.volume_m3, 0.8 * full);
  EXPECT_LT(c.parts[0].checks.volume_m3, 1.0 * full);
}

TEST(PartitionCompleter, HammerPartsSumToTheHammer) {
  const std::string path = test::scratch_dir("PartitionHammer") + "/hammer.glb";
  test::make_hammer().write(path);
  Result<Model> model = load_model(path);
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  std::vector<Part> parts(2);
  parts[0].label = kMetal;  // material 0: steel head
  parts[1].label = kWood;   // material 1: oak handle
  for (int f = 0; f < model->mesh.num_faces(); ++f)
    parts[static_cast<std::size_t>(model->mesh.face_source[static_cast<std::size_t>(f)].material)].faces.push_back(f);
  const Completion c = run_partition(model->mesh, parts);
  ASSERT_EQ(c.parts.size(), 2u);
  for (const CompletedPart& p : c.parts) expect_watertight(p);
  const double head = 0.12 * 0.04 * 0.035;
  const double handle = volume_of(model->mesh) - head;  // the 24-sided prism as tessellated
  EXPECT_NEAR(c.parts[0].checks.volume_m3 / head, 1.0, 0.02);
  EXPECT_NEAR(c.parts[1].checks.volume_m3 / handle, 1.0, 0.03);
  EXPECT_NEAR(c.parts_volume_m3 / volume_of(model->mesh), 1.0, 0.02);
}

TEST(PartitionCompleter, IsDeterministic) {
  const Mesh sphere = test::sphere_mesh(0.1, 32);
  const Completion a = run_partition(sphere, test::single_part(sphere, kWood), {{"resolution", "48"}});
  const Completion b = run_partition(sphere, test::single_part(sphere, kWood), {{"resolution", "48"}});
  ASSERT_EQ(a.parts.size(), 1u);
  ASSERT_EQ(b.parts.size(), 1u);
  EXPECT_EQ(a.parts[0].mesh.positions, b.parts[0].mesh.positions);
  EXPECT_EQ(a.parts[0].mesh.triangles, b.parts[0].mesh.triangles);
}

TEST(PartitionCompleter, RejectsBadInputAndSettings) {
  const Mesh box = test::box_mesh({0, 0, 0}, {1, 1, 1});
  auto c = std::move(*make_completer("partition"));
  std::vector<Part> parts = test::single_part(box, kWood);
  parts[0].faces.push_back(99);
  CompletionInput in{&box, &parts, nullptr};
  Result<Completion> r = c->complete(in);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("face 99"), std::string::npos) << r.status().message();

  std::vector<Part> twice = test::single_part(box, kWood);
  twice.push_back(twice[0]);
  in.parts = &twice;
  EXPECT_EQ(c->complete(in).status().code(), StatusCode::kInvalidArgument);

  const Mesh empty;
  std::vector<Part> none;
  in = {&empty, &none, nullptr};
  EXPECT_EQ(c->complete(in).status().code(), StatusCode::kInvalidArgument);

  EXPECT_FALSE(make_completer("partition", {{"gap", "0.5"}}).ok());
  EXPECT_FALSE(make_completer("partition", {{"resolution", "abc"}}).ok());
  EXPECT_FALSE(make_completer("partition", {{"colour", "red"}}).ok());
  EXPECT_FALSE(make_completer("no-such-completer").ok());
}

// Every part of every shared asset completes, passes the checks, and the
// parts' volumes add up to the closed object's.
class PartitionAssets : public testing::TestWithParam<const char*> {};

TEST_P(PartitionAssets, EveryPartIsWatertightAndTheyTileTheObject) {
  const std::string name = GetParam();
  Result<Model> model = load_model(test::asset_path(name));
  ASSERT_TRUE(model.ok()) << model.status().to_string();
  const std::vector<Part> parts = test::ground_truth_parts(*model, name);
  ASSERT_FALSE(parts.empty());
  const Completion c = run_partition(model->mesh, parts);
  ASSERT_EQ(c.parts.size(), parts.size());
  for (const CompletedPart& p : c.parts) {
    expect_watertight(p);
    EXPECT_GT(p.checks.volume_m3, 0.0);
    // Every part stays inside the object (up to a cell).
    Eigen::AlignedBox3d object = bounds(model->mesh);
    object.extend(object.min() - Eigen::Vector3d::Constant(c.grid_spacing_m));
    object.extend(object.max() + Eigen::Vector3d::Constant(c.grid_spacing_m));
    EXPECT_TRUE(object.contains(bounds(p.mesh))) << "part " << p.part;
  }
  EXPECT_GT(c.object_volume_m3, 0.0);
  EXPECT_NEAR(c.parts_volume_m3 / c.object_volume_m3, 1.0, 0.02);
  // Where the asset itself is a closed surface, the object keeps its volume.
  const MeshChecks original = check_closed_mesh(model->mesh);
  if (original.closed && original.outward)
    EXPECT_NEAR(c.object_volume_m3 / original.volume_m3, 1.0, 0.02) << name << " is closed";
}

INSTANTIATE_TEST_SUITE_P(SharedAssets, PartitionAssets,
                         testing::Values("SheenChair", "GlamVelvetSofa", "GlassHurricaneCandleHolder", "WaterBottle",
                                         "Avocado"));

}  // namespace
}  // namespace g2p
