// Contacts in MuJoCo: concave fixtures (a bowl, a cup, a chair-like frame, a
// U channel, a torus) exported with their convex decomposition, probe balls dropped
// onto them with check_contacts_in_mujoco, and the free object dropped onto a
// plane. The same fixtures exported as one convex hull show the failure the
// decomposition removes: balls resting on the bowl's rim or the hull's slope.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "decompose/decompose_fixtures.h"
#include "g2p/decompose.h"
#include "g2p/export.h"
#include "g2p/properties.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// A one-part asset of `closed` (solid, 1000 kg/m^3) decomposed by `backend`
// with the pipeline's per-object depth (1 % of the diagonal), written as MJCF.
std::string export_fixture(const Mesh& closed, const std::string& name, const std::string& backend) {
  Result<std::unique_ptr<Decomposer>> decomposer = make_decomposer(backend);
  EXPECT_TRUE(decomposer.ok());
  DecomposeOptions options;
  options.min_depth_m = 0.01 * bounds(closed).diagonal().norm();
  Result<ConvexDecomposition> hulls = decompose_part(closed, **decomposer, options);
  EXPECT_TRUE(hulls.ok()) << hulls.status().to_string();
  Result<MassProperties> mass = solid_mass_properties(closed, 1000.0);
  EXPECT_TRUE(mass.ok()) << mass.status().to_string();
  SimulationAsset asset;
  asset.name = name;
  AssetPart part;
  part.part = 0;
  part.name = "part_0_Plastic";
  part.material = "Plastic";
  part.closed = closed;
  part.visual = closed;
  part.collision = *hulls;
  part.properties.density_kg_m3 = 1000.0;
  part.mass = *mass;
  asset.parts.push_back(part);
  asset.total = combine({*mass});
  const std::string dir = test::scratch_dir("Contacts_" + name + "_" + backend);
  EXPECT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  return dir + "/" + name + ".xml";
}

ContactCheck check(const std::string& mjcf, std::vector<Eigen::Vector2d> points, int grid = 0, double radius = 0,
                   double seconds = 3.0) {
  ContactCheckOptions options;
  options.seconds = seconds;
  options.grid = grid;
  options.points = std::move(points);
  options.ball_radius_m = radius;
  options.places = false;  // only the balls asked for (resting_places_test.cpp and seats_test.cpp drop the rest)
  // Balls that stop rolling on a level hard surface (2 mm of rolling
  // friction): these fixtures test the hulls' shape. A user's ball, MuJoCo's
  // default, keeps rolling on level Plastic as a marble on a table does
  // (seats_test.cpp drops those on real seats).
  options.ball_rolling_friction_m = 0.002;
  Result<ContactCheck> c = check_contacts_in_mujoco(mjcf, options);
  EXPECT_TRUE(c.ok()) << c.status().to_string();
  return c.ok() ? *c : ContactCheck{};
}

// Every ball at rest at the end and the dropped object above the plane.
void expect_settled(const ContactCheck& c) {
  for (const BallProbe& b : c.balls)
    EXPECT_LT(b.final_speed_m_s, 0.005) << "ball from (" << b.start.x() << ", " << b.start.y() << ")";
  EXPECT_TRUE(c.drop.dropped);
  EXPECT_TRUE(c.object_above_plane) << "rests " << c.drop.resting_lowest_m << " m above the plane";
  EXPECT_GT(c.drop.resting_lowest_m, -0.01);
}

TEST(Contacts, BallRestsInsideTheBowl) {
  const Mesh bowl = test::bowl_mesh(0.1, 0.012);  // inner bottom at z = 0.012, rim at 0.1
  const ContactCheck c = check(export_fixture(bowl, "bowl", "voxel-cut"), {{0, 0}, {0.03, 0.01}});
  ASSERT_EQ(c.balls.size(), 2u);
  // The ball over the middle rests within 1.5 radii of the inner bottom (on
  // the hulls' flat faces, which contacts scaled to the bowl no longer let
  // it sink into)...
  EXPECT_TRUE(c.balls[0].on_object);
  EXPECT_LT(c.balls[0].rest.z() - c.balls[0].radius_m - 0.012, 1.5 * c.balls[0].radius_m) << c.balls[0].rest.z();
  // ...and the one off the middle within a centimetre of the inner surface
  // below where it stopped: 16 flat-faced hulls follow the curved inside to
  // a few millimetres and may hold a ball on the slope (one hull leaves it
  // 7 cm up, on the rim's plane).
  const BallProbe& side = c.balls[1];
  EXPECT_TRUE(side.on_object);
  const double r2 = side.rest.head<2>().squaredNorm();
  ASSERT_LT(r2, 0.088 * 0.088);
  const double inner_surface = 0.1 - std::sqrt(0.088 * 0.088 - r2);
  EXPECT_LT(side.rest.z() - side.radius_m - inner_surface, 0.01) << "rests at z " << side.rest.z();
  expect_settled(c);

  // One convex hull: the same ball stays up at the rim's plane.
  const ContactCheck one = check(export_fixture(bowl, "bowl", "hull"), {{0, 0}});
  ASSERT_EQ(one.balls.size(), 1u);
  EXPECT_GT(one.balls[0].rest.z() - one.balls[0].radius_m, 0.09);
}

TEST(Contacts, BallRestsOnTheCupsBottom) {
  const Mesh cup = test::cup_mesh(0.04, 0.1, 0.005, 0.008);  // inner bottom at z = 0.008
  const ContactCheck c = check(export_fixture(cup, "cup", "voxel-cut"), {{0, 0}});
  ASSERT_EQ(c.balls.size(), 1u);
  const BallProbe& b = c.balls[0];
  EXPECT_TRUE(b.on_object);
  EXPECT_LT(b.rest.z() - b.radius_m - 0.008, b.radius_m) << "rests at z " << b.rest.z();
  expect_settled(c);
}

// A user's balls (MuJoCo's default geom, no rolling friction of their own)
// dropped over the cavity the check finds in a bowl and in a mug with a
// handle: nine each, of 1 and 2 cm across, all at rest inside.
TEST(Contacts, UsersBallsDroppedIntoTheBowlAndTheMugRestInside) {
  const std::pair<const char*, Mesh> fixtures[] = {{"bowl", test::bowl_mesh(0.1, 0.012)}, {"mug", test::mug_mesh()}};
  for (const auto& [name, mesh] : fixtures) {
    const std::string mjcf = export_fixture(mesh, name, "voxel-cut");
    for (const double radius : {0.005, 0.01}) {
      ContactCheckOptions o;
      o.grid = 0;
      o.ball_radius_m = radius;
      Result<ContactCheck> c = check_contacts_in_mujoco(mjcf, o);
      ASSERT_TRUE(c.ok()) << c.status().to_string();
      const PlaceProbe* cavity = nullptr;
      for (const PlaceProbe& p : c->places)
        if (p.place.kind == RestingPlaceKind::kCavity && cavity == nullptr) cavity = &p;
      ASSERT_NE(cavity, nullptr) << name << ": no cavity\n" << contact_check_text(*c, mjcf, o);
      EXPECT_EQ(cavity->dropped, 9) << name;
      EXPECT_EQ(cavity->stayed, cavity->dropped) << name << ", balls of radius " << radius << "\n"
                                                 << contact_check_text(*c, mjcf, o);
      std::printf("%s, balls %.0f mm across: %s %.3f m deep, %d of %d at rest inside\n", name, 2000 * radius,
                  cavity->place.name.c_str(), cavity->place.depth_m, cavity->stayed, cavity->dropped);
    }
  }
}

TEST(Contacts, BallRestsOnTheSeat) {
  const Mesh chair = test::chair_mesh(0.05f);  // seat top at 0.45 m, backrest up to 0.85 m at y 0.35..0.4
  const std::string mjcf = export_fixture(chair, "chair", "voxel-cut");
  // A 2 cm ball over the middle of the seat and one nearer the backrest.
  const ContactCheck c = check(mjcf, {{0.2, 0.15}, {0.2, 0.28}, {0.1, 0.1}}, 0, 0.01);
  ASSERT_EQ(c.balls.size(), 3u);
  for (const BallProbe& b : c.balls) {
    EXPECT_TRUE(b.on_object);
    EXPECT_NEAR(b.rest.z() - b.radius_m, 0.45, 0.01) << "ball from (" << b.start.x() << ", " << b.start.y() << ")";
    EXPECT_GT(b.rest.x(), 0.0);  // still over the seat
    EXPECT_LT(b.rest.x(), 0.4);
    EXPECT_GT(b.rest.y(), 0.0);
    EXPECT_LT(b.rest.y(), 0.35);
  }
  expect_settled(c);

  // One convex hull: the ball near the backrest lands on the hull's slope
  // from the backrest's top to the seat's front edge, far above the seat.
  const ContactCheck one = check(export_fixture(chair, "chair", "hull"), {{0.2, 0.28}}, 0, 0.01);
  ASSERT_EQ(one.balls.size(), 1u);
  EXPECT_FALSE(std::abs(one.balls[0].rest.z() - one.balls[0].radius_m - 0.45) < 0.01 && one.balls[0].on_object);
}

TEST(Contacts, BallRestsInTheChannel) {
  const Mesh u = test::u_channel_mesh(0.02f);  // base top at z = 0.02, open between x 0.02 and 0.08
  const ContactCheck c = check(export_fixture(u, "channel", "voxel-cut"), {{0.05, 0.03}}, 0, 0.008);
  ASSERT_EQ(c.balls.size(), 1u);
  EXPECT_TRUE(c.balls[0].on_object);
  EXPECT_NEAR(c.balls[0].rest.z() - c.balls[0].radius_m, 0.02, 0.004);
  expect_settled(c);
}

TEST(Contacts, BallFallsThroughTheTorusHole) {
  // The hole is 15 cm across (tube centre radius 10 cm, tube 2.5 cm); the
  // floor lies at the torus's lowest point.
  const Mesh torus = test::torus_mesh(0.1, 0.025);
  const ContactCheck c = check(export_fixture(torus, "torus", "voxel-cut"), {{0, 0}}, 0, 0.01);
  ASSERT_EQ(c.balls.size(), 1u);
  EXPECT_TRUE(c.balls[0].on_floor);
  EXPECT_FALSE(c.balls[0].on_object);
  EXPECT_LT(c.balls[0].rest.head<2>().norm(), 0.075 - 0.01) << "still under the hole";
  expect_settled(c);

  // One convex hull closes the hole: the ball stays on top of it.
  const ContactCheck one = check(export_fixture(torus, "torus", "hull"), {{0, 0}}, 0, 0.01);
  ASSERT_EQ(one.balls.size(), 1u);
  EXPECT_TRUE(one.balls[0].on_object);
  EXPECT_FALSE(one.balls[0].on_floor);
}

TEST(Contacts, GridOfBallsOverTheBowlAllSettle) {
  // 5 s: on contacts scaled to the bowl (#50) a 5 mm ball rolls about its
  // plastic inside for 3 to 5 s before it stops.
  const ContactCheck c = check(export_fixture(test::bowl_mesh(0.1, 0.012), "bowl", "voxel-cut"), {}, 4, 0, 5.0);
  ASSERT_EQ(c.balls.size(), 16u);
  EXPECT_NEAR(c.balls[0].radius_m, 0.005, 1e-9);  // 2 % of 0.2 m is under the 5 mm floor
  expect_settled(c);
  // Balls over the bowl end in it or on its rim, those past it on the floor.
  for (const BallProbe& b : c.balls) EXPECT_TRUE(b.on_object || b.on_floor);
}

TEST(Contacts, BadInputIsReported) {
  EXPECT_EQ(check_contacts_in_mujoco("/nonexistent/x.xml").status().code(), StatusCode::kNotFound);
  ContactCheckOptions none;
  none.grid = 0;
  none.places = false;
  const std::string mjcf = export_fixture(test::u_channel_mesh(0.02f), "channel", "hull");
  Result<ContactCheck> c = check_contacts_in_mujoco(mjcf, none);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("--balls"), std::string::npos) << c.status().to_string();
  ContactCheckOptions rolling;
  rolling.ball_rolling_friction_m = -1;
  EXPECT_EQ(check_contacts_in_mujoco(mjcf, rolling).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p
