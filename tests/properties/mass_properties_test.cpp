// Mass properties against closed forms.
#include "g2p/properties.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "g2p/io.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

void expect_relative(double got, double want, double tolerance, const char* what) {
  EXPECT_NEAR(got / want, 1.0, tolerance) << what << ": " << got << " vs " << want;
}

TEST(MassProperties, UnitCubeAndOffsetCube) {
  for (const Eigen::Vector3f offset : {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(3, -2, 5)}) {
    std::vector<Eigen::Vector3f> p;
    std::vector<std::array<unsigned, 3>> t;
    test::box_geometry(offset, offset + Eigen::Vector3f::Ones(), p, t);
    Result<MassProperties> m = solid_mass_properties(test::mesh_from_geometry(p, t), 1000.0);
    ASSERT_TRUE(m.ok()) << m.status().to_string();
    EXPECT_NEAR(m->mass_kg, 1000.0, 1e-9);
    EXPECT_NEAR(m->volume_m3, 1.0, 1e-12);
    EXPECT_NEAR(m->area_m2, 6.0, 1e-9);
    EXPECT_TRUE(m->center_of_mass.isApprox((offset + Eigen::Vector3f::Constant(0.5f)).cast<double>(), 1e-9));
    // A cube's inertia about its centre: m a^2 / 6 on the diagonal, no products.
    EXPECT_TRUE(m->inertia.isApprox(Eigen::Matrix3d::Identity() * 1000.0 / 6.0, 1e-9)) << m->inertia;
  }
}

TEST(MassProperties, SphereCylinderAndShellWithinTessellationError) {
  // Sphere r = 0.5 m, steel: I = 2/5 m r^2. 128 rings: tessellation error well under 0.1 %.
  const double r = 0.5;
  Result<MassProperties> s = solid_mass_properties(test::sphere_mesh(r, 128), 7800.0);
  ASSERT_TRUE(s.ok());
  const double volume = 4.0 / 3.0 * M_PI * r * r * r;
  expect_relative(s->volume_m3, volume, 1e-3, "sphere volume");
  expect_relative(s->inertia(0, 0), 0.4 * s->mass_kg * r * r, 1e-3, "sphere Ixx");
  expect_relative(s->inertia(2, 2), 0.4 * s->mass_kg * r * r, 1e-3, "sphere Izz");
  EXPECT_LT(s->center_of_mass.norm(), 1e-9);

  // Thin spherical shell: I = 2/3 m r^2, m = rho A t.
  Result<MassProperties> shell = shell_mass_properties(test::sphere_mesh(r, 128), 2500.0, 0.004);
  ASSERT_TRUE(shell.ok());
  expect_relative(shell->mass_kg, 2500.0 * 4.0 * M_PI * r * r * 0.004, 1e-3, "shell mass");
  expect_relative(shell->inertia(1, 1), 2.0 / 3.0 * shell->mass_kg * r * r, 1e-3, "shell Iyy");

  // Closed cylinder (axis along glTF +Y), r = 0.1, h = 0.6: Iyy = m r^2 / 2, Ixx = m (3 r^2 + h^2) / 12.
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::cylinder_geometry(0.1f, 0.f, 0.6f, 512, p, t);
  Result<MassProperties> c = solid_mass_properties(test::mesh_from_geometry(p, t), 700.0);
  ASSERT_TRUE(c.ok());
  expect_relative(c->volume_m3, M_PI * 0.01 * 0.6, 1e-3, "cylinder volume");
  expect_relative(c->inertia(1, 1), 0.5 * c->mass_kg * 0.01, 1e-3, "cylinder Iyy");
  expect_relative(c->inertia(0, 0), c->mass_kg * (3 * 0.01 + 0.36) / 12.0, 1e-3, "cylinder Ixx");
  EXPECT_NEAR(c->center_of_mass.y(), 0.3, 1e-6);
  // Principal axes: the symmetry axis carries the smallest moment.
  EXPECT_NEAR(std::abs(c->principal_axes().col(0).y()), 1.0, 1e-6);
  EXPECT_NEAR(c->principal_axes().determinant(), 1.0, 1e-9);
}

TEST(MassProperties, TwoMaterialHammerBalancesInItsHead) {
  const std::string dir = test::scratch_dir("MassProperties.Hammer");
  test::make_hammer().write(dir + "/hammer.glb");
  Result<Model> model = load_model(dir + "/hammer.glb");
  ASSERT_TRUE(model.ok());
  // One mesh per material (steel 7800, oak 700 kg/m^3).
  std::map<int, Mesh> parts;
  for (int f = 0; f < model->mesh.num_faces(); ++f) {
    Mesh& part = parts[model->mesh.face_source[f].material];
    part.positions = model->mesh.positions;  // unused vertices do not count
    part.triangles.push_back(model->mesh.triangles[f]);
  }
  const MassProperties head = *solid_mass_properties(parts[0], 7800.0);
  const MassProperties handle = *solid_mass_properties(parts[1], 700.0);
  const MassProperties hammer = combine({head, handle});
  EXPECT_NEAR(hammer.mass_kg, head.mass_kg + handle.mass_kg, 1e-12);
  // The head spans z in [0.30, 0.34] m (after the Y-up to Z-up import); the centre of mass lies in it.
  EXPECT_GT(hammer.center_of_mass.z(), 0.30);
  EXPECT_LT(hammer.center_of_mass.z(), 0.34);
  EXPECT_GT(hammer.center_of_mass.z(), 0.5 * (0.0 + 0.34));  // far above the geometric middle
  // Both parts are symmetric about the hammer's axis, so the centre of mass
  // lies on it exactly, not the rounding's nanometre fractions off it
  // (-7e-21 m printed by `g2p run` until 2026-11-29; 5e-12 m for this handle).
  EXPECT_EQ(head.center_of_mass.x(), 0.0);
  EXPECT_EQ(head.center_of_mass.y(), 0.0);
  EXPECT_EQ(hammer.center_of_mass.x(), 0.0);
  EXPECT_EQ(hammer.center_of_mass.y(), 0.0);
  // Parallel axis: combined inertia about x exceeds the sum of the parts' own.
  EXPECT_GT(hammer.inertia(0, 0), head.inertia(0, 0) + handle.inertia(0, 0));
}

// combine's parallel-axis terms, products of inertia included, against two
// checks that share no code with it: one integration of both boxes as one
// mesh (equal densities), and the boxes' closed forms (unequal densities).
TEST(MassProperties, CombinedPartsEqualTheWholeAboutItsCentre) {
  const Eigen::Vector3f a_min(0, 0, 0), a_max(1, 1, 1), b_min(1, 0.25f, 0.5f), b_max(3, 0.75f, 2);
  std::vector<Eigen::Vector3f> pa, pb;
  std::vector<std::array<unsigned, 3>> ta, tb;
  test::box_geometry(a_min, a_max, pa, ta);
  test::box_geometry(b_min, b_max, pb, tb);
  std::vector<Eigen::Vector3f> both = pa;
  both.insert(both.end(), pb.begin(), pb.end());
  std::vector<std::array<unsigned, 3>> tboth = ta;
  for (std::array<unsigned, 3> t : tb) tboth.push_back({t[0] + 8u, t[1] + 8u, t[2] + 8u});
  ASSERT_EQ(pa.size(), 8u);
  const Mesh box_a = test::mesh_from_geometry(pa, ta), box_b = test::mesh_from_geometry(pb, tb);
  const MassProperties whole = *solid_mass_properties(test::mesh_from_geometry(both, tboth), 1000.0);
  const MassProperties joined = combine({*solid_mass_properties(box_a, 1000.0), *solid_mass_properties(box_b, 1000.0)});
  EXPECT_NEAR(joined.mass_kg, whole.mass_kg, 1e-9);
  EXPECT_TRUE(joined.center_of_mass.isApprox(whole.center_of_mass, 1e-12));
  EXPECT_TRUE(joined.inertia.isApprox(whole.inertia, 1e-9)) << joined.inertia << "\nvs\n" << whole.inertia;
  EXPECT_GT(std::abs(whole.inertia(0, 2)), 10.0);  // the offset boxes have products of inertia

  // Box a of steel, box b of oak: m/12 (b^2 + c^2, ...) about each centre, moved
  // to the common centre by m (|d|^2 I - d d^T).
  const MassProperties mixed = combine({*solid_mass_properties(box_a, 7800.0), *solid_mass_properties(box_b, 700.0)});
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  double mass = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  const struct {
    Eigen::Vector3d lo, hi;
    double density;
  } boxes[] = {{a_min.cast<double>(), a_max.cast<double>(), 7800.0},
               {b_min.cast<double>(), b_max.cast<double>(), 700.0}};
  for (const auto& b : boxes) {
    const Eigen::Vector3d s = b.hi - b.lo;
    mass += b.density * s.prod();
    moment += b.density * s.prod() * 0.5 * (b.lo + b.hi);
  }
  const Eigen::Vector3d centre = moment / mass;
  for (const auto& b : boxes) {
    const Eigen::Vector3d s = b.hi - b.lo, d = 0.5 * (b.lo + b.hi) - centre;
    const double m = b.density * s.prod();
    const Eigen::Vector3d own(s.y() * s.y() + s.z() * s.z(), s.x() * s.x() + s.z() * s.z(),
                              s.x() * s.x() + s.y() * s.y());
    expected += Eigen::Matrix3d(own.asDiagonal()) * (m / 12.0);
    expected += m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
  }
  EXPECT_NEAR(mixed.mass_kg, mass, 1e-9 * mass);
  EXPECT_TRUE(mixed.center_of_mass.isApprox(centre, 1e-12));
  EXPECT_TRUE(mixed.inertia.isApprox(expected, 1e-9)) << mixed.inertia << "\nvs\n" << expected;
}

TEST(MassProperties, AFillSettlesAtTheBottomOfItsVolume) {
  // A 1 x 1 x 2 m tank half full of water holds a 1 m cube of water at the bottom.
  const Mesh tank = test::box_mesh({-0.5f, -0.5f, 0.f}, {0.5f, 0.5f, 2.f});
  Result<MassProperties> half = fill_mass_properties(tank, 1000.0, 1.0);
  ASSERT_TRUE(half.ok()) << half.status().to_string();
  EXPECT_NEAR(half->mass_kg, 1000.0, 1e-6);
  EXPECT_NEAR(half->volume_m3, 1.0, 1e-8);
  EXPECT_TRUE(half->center_of_mass.isApprox(Eigen::Vector3d(0, 0, 0.5), 1e-8)) << half->center_of_mass.transpose();
  EXPECT_TRUE(half->inertia.isApprox(Eigen::Matrix3d::Identity() * 1000.0 / 6.0, 1e-6)) << half->inertia;
  Result<MassProperties> low = fill_mass_properties(tank, 1000.0, 0.3);  // found over many bisection steps
  ASSERT_TRUE(low.ok());
  EXPECT_NEAR(low->volume_m3, 0.3, 1e-8);
  EXPECT_NEAR(low->center_of_mass.z(), 0.15, 1e-8);
  // Levels through a ring of vertices: a tank whose sides are split at `ring`
  // (the level lands on the ring at the first step for 1.0, after many for 0.6).
  for (const float ring : {1.0f, 0.6f}) {
    Mesh split;
    const float corner[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};  // counter-clockwise
    for (const float z : {0.f, ring, 2.f})
      for (const auto& c : corner) split.positions.emplace_back(c[0], c[1], z);
    auto at = [](int layer, int i) { return 4 * layer + (i % 4); };
    for (int layer = 0; layer < 2; ++layer)
      for (int i = 0; i < 4; ++i) {
        split.triangles.emplace_back(at(layer, i), at(layer, i + 1), at(layer + 1, i + 1));
        split.triangles.emplace_back(at(layer, i), at(layer + 1, i + 1), at(layer + 1, i));
      }
    split.triangles.emplace_back(at(0, 0), at(0, 2), at(0, 1));
    split.triangles.emplace_back(at(0, 0), at(0, 3), at(0, 2));
    split.triangles.emplace_back(at(2, 0), at(2, 1), at(2, 2));
    split.triangles.emplace_back(at(2, 0), at(2, 2), at(2, 3));
    ASSERT_NEAR(solid_mass_properties(split, 1.0)->volume_m3, 2.0, 1e-9);
    Result<MassProperties> to_ring = fill_mass_properties(split, 1000.0, ring);
    ASSERT_TRUE(to_ring.ok()) << to_ring.status().to_string();
    EXPECT_NEAR(to_ring->volume_m3, ring, 1e-8) << ring;
    EXPECT_NEAR(to_ring->center_of_mass.z(), 0.5 * ring, 1e-8) << ring;
  }
  // Full: the solid itself.
  Result<MassProperties> full = fill_mass_properties(tank, 1000.0, 2.0);
  ASSERT_TRUE(full.ok());
  EXPECT_NEAR(full->center_of_mass.z(), 1.0, 1e-9);

  // A sphere half full: a hemisphere, centre of mass 3 r / 8 below the centre; a quarter
  // full: the cap of height h with pi h^2 (3 r - h) / 3 = pi r^3 / 3, centroid
  // 3 (2 r - h)^2 / (4 (3 r - h)) below the centre.
  const double r = 0.5;
  const Mesh ball = test::sphere_mesh(r, 128);
  const double volume = 4.0 / 3.0 * M_PI * r * r * r;
  Result<MassProperties> hemisphere = fill_mass_properties(ball, 1000.0, 0.5 * volume);
  ASSERT_TRUE(hemisphere.ok());
  EXPECT_NEAR(hemisphere->center_of_mass.z(), -3.0 * r / 8.0, 1e-3 * r);
  EXPECT_NEAR(hemisphere->center_of_mass.head<2>().norm(), 0.0, 1e-6);
  double lo = 0, hi = 2 * r;  // the cap's height, by bisection on its closed form
  for (int i = 0; i < 100; ++i) {
    const double h = 0.5 * (lo + hi);
    (M_PI * h * h * (3 * r - h) / 3 < 0.25 * volume ? lo : hi) = h;
  }
  const double h = lo;
  Result<MassProperties> cap = fill_mass_properties(ball, 1000.0, 0.25 * volume);
  ASSERT_TRUE(cap.ok());
  expect_relative(cap->mass_kg, 250.0 * volume, 1e-6, "cap mass");
  EXPECT_NEAR(cap->center_of_mass.z(), -3 * (2 * r - h) * (2 * r - h) / (4 * (3 * r - h)), 2e-3 * r);

  // Bad fills: none, more than the volume, a mesh wound inward.
  EXPECT_EQ(fill_mass_properties(tank, 1000.0, 0.0).status().code(), StatusCode::kInvalidArgument);
  Result<MassProperties> over = fill_mass_properties(tank, 1000.0, 2.5);
  EXPECT_EQ(over.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(over.status().message().find("at most all of it"), std::string::npos) << over.status().message();
  Mesh inward = tank;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  Result<MassProperties> inside_out = fill_mass_properties(inward, 1000.0, 0.5);
  EXPECT_EQ(inside_out.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(inside_out.status().message().find("fill: "), std::string::npos) << inside_out.status().message();
}

TEST(MassProperties, Errors) {
  EXPECT_EQ(solid_mass_properties(Mesh{}, 1000).status().code(), StatusCode::kInvalidArgument);
  Mesh inward = test::box_mesh({0, 0, 0}, {1, 1, 1});
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  Result<MassProperties> bad = solid_mass_properties(inward, 1000);
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("closed and wound outward"), std::string::npos);
  EXPECT_EQ(solid_mass_properties(test::box_mesh({0, 0, 0}, {1, 1, 1}), -5).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(shell_mass_properties(test::box_mesh({0, 0, 0}, {1, 1, 1}), 1000, 0).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(combine({}).mass_kg, 0.0);
}

}  // namespace
}  // namespace g2p
