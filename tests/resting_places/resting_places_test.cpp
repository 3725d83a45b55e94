// Resting places (resting_places.h) on height maps drawn here: a bowl and a
// tray hold cavities, a chair's seat is a surface and its narrow backrest top
// is left out for a ball wider than it, a dome's cap is a surface and its
// flanks are not, and probes lie inside the place they were made for.
#include "g2p/resting_places.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace g2p {
namespace {

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

// A map of `cells` x `cells` over [0, size]^2 with the floor at 0; z(x, y) in
// metres, NaN where there is nothing.
HeightMap draw(int cells, double size, const std::function<double(double, double)>& z) {
  HeightMap map;
  map.width = map.height = cells;
  map.cell_m = size / cells;
  map.floor_z = 0.0;
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      const Eigen::Vector2d c = map.centre(x, y);
      map.z.push_back(z(c.x(), c.y()));
    }
  return map;
}

int cell_of(const HeightMap& map, const Eigen::Vector2d& p) {
  const int x = static_cast<int>(std::floor((p.x() - map.origin.x()) / map.cell_m));
  const int y = static_cast<int>(std::floor((p.y() - map.origin.y()) / map.cell_m));
  return y * map.width + x;
}

void expect_probes_inside(const HeightMap& map, const RestingPlace& p) {
  ASSERT_FALSE(p.probes.empty()) << p.name;
  for (const Eigen::Vector2d& at : p.probes)
    EXPECT_TRUE(std::binary_search(p.cells.begin(), p.cells.end(), cell_of(map, at)))
        << p.name << ": probe " << at.transpose() << " lies outside it";
}

TEST(RestingPlaces, ABowlIsOneCavityAsDeepAsItsRim) {
  // A bowl 0.3 m across on the floor: a spherical inside from a bottom at
  // 0.02 m up to a rim at 0.1 m, a 1 cm wall.
  const HeightMap map = draw(90, 0.4, [](double x, double y) {
    const double r = std::hypot(x - 0.2, y - 0.2);
    if (r > 0.15) return kNone;
    if (r > 0.14) return 0.1;
    return 0.02 + 0.08 * (r / 0.14) * (r / 0.14);
  });
  RestingPlaceOptions o;
  o.probe_clearance_m = 0.01;  // a 2 cm ball: wider than the rim
  Result<std::vector<RestingPlace>> places = find_resting_places(map, o);
  ASSERT_TRUE(places.ok()) << places.status().to_string();
  ASSERT_EQ(places->size(), 1u);
  const RestingPlace& bowl = places->front();
  EXPECT_EQ(bowl.kind, RestingPlaceKind::kCavity);
  EXPECT_EQ(bowl.name, "cavity 1");
  EXPECT_NEAR(bowl.rim_z_m, 0.1, 1e-9);
  EXPECT_NEAR(bowl.depth_m, 0.08, 0.002);
  // The cells deeper than 1 cm (5 % of the bowl's height is 5 mm): r < 0.124 m.
  EXPECT_NEAR(bowl.area_m2, M_PI * 0.131 * 0.131, 0.01);
  expect_probes_inside(map, bowl);
  EXPECT_LT((bowl.probes.front() - Eigen::Vector2d(0.2, 0.2)).norm(), 0.01);  // the deepest-inside point
  EXPECT_EQ(bowl.probes.size(), 9u);
  // A thinner ball finds the rim's top too, a surface 1 cm wide.
  Result<std::vector<RestingPlace>> thin = find_resting_places(map);
  ASSERT_TRUE(thin.ok());
  ASSERT_EQ(thin->size(), 2u);
  EXPECT_EQ((*thin)[1].kind, RestingPlaceKind::kSurface);
  EXPECT_NEAR((*thin)[1].z_m, 0.1, 1e-9);
  EXPECT_NEAR((*thin)[1].inner_radius_m, 0.005, 0.003);

  // A ball at the bottom is in it; one on the floor beside it is not.
  EXPECT_EQ(resting_place_at(map, *places, {0.2, 0.2, 0.02}, 0.01), 0);
  EXPECT_EQ(resting_place_at(map, *places, {0.38, 0.38, 0.0}, 0.01), -1);
}

TEST(RestingPlaces, AChairsSeatIsASurfaceAndItsNarrowBackrestTopIsLeftOutForAWideBall) {
  // Seat 0.45 x 0.40 m at 0.45 m sloping 5 degrees down to the back (+y);
  // backrest 4 cm deep up to 0.85 m behind it; nothing under the seat shows.
  const double tilt = std::tan(5.0 * M_PI / 180.0);
  auto chair = [&](double x, double y) {
    if (x < 0.05 || x > 0.5 || y < 0.05 || y > 0.49) return kNone;
    if (y > 0.45) return 0.85;
    return 0.45 - tilt * (y - 0.05);
  };
  const HeightMap map = draw(110, 0.55, chair);
  RestingPlaceOptions o;
  o.probe_clearance_m = 0.025;  // a 5 cm ball
  Result<std::vector<RestingPlace>> places = find_resting_places(map, o);
  ASSERT_TRUE(places.ok()) << places.status().to_string();
  ASSERT_EQ(places->size(), 1u);
  const RestingPlace& seat = places->front();
  EXPECT_EQ(seat.kind, RestingPlaceKind::kSurface);
  EXPECT_EQ(seat.name, "surface 1");
  EXPECT_NEAR(seat.z_m, 0.45 - tilt * 0.2, 0.005);
  EXPECT_NEAR(seat.slope_deg, 5.0, 0.5);
  EXPECT_NEAR(seat.area_m2, 0.45 * 0.40, 0.01);
  EXPECT_NEAR(seat.inner_radius_m, 0.2, 0.01);
  expect_probes_inside(map, seat);
  // Every probe clear of the seat's edge by the ball and then some.
  for (const Eigen::Vector2d& at : seat.probes) {
    EXPECT_GT(std::min({at.x() - 0.05, 0.5 - at.x(), at.y() - 0.05, 0.45 - at.y()}), 0.025) << at.transpose();
  }
  // Probes spread: no two closer than a tenth of the seat.
  for (std::size_t i = 0; i < seat.probes.size(); ++i)
    for (std::size_t j = i + 1; j < seat.probes.size(); ++j) EXPECT_GT((seat.probes[i] - seat.probes[j]).norm(), 0.04);

  // A thin ball finds the backrest's top too (4 cm deep, inner radius 2 cm).
  Result<std::vector<RestingPlace>> thin = find_resting_places(map);
  ASSERT_TRUE(thin.ok());
  ASSERT_EQ(thin->size(), 2u);
  EXPECT_NEAR((*thin)[1].z_m, 0.85, 1e-9);

  // A ball resting on the seat is on it; one on the backrest top is not.
  EXPECT_EQ(resting_place_at(map, *places, {0.3, 0.2, chair(0.3, 0.2)}, 0.01), 0);
  EXPECT_EQ(resting_place_at(map, *places, {0.3, 0.2, 0.7}, 0.01), -1);
  EXPECT_EQ(resting_place_at(map, *places, {0.3, 0.47, 0.85}, 0.01), -1);
}

TEST(RestingPlaces, ATrayHoldsACavityAndADomeOnlyItsCap) {
  // A tray: a 2 cm lip around a flat floor at 1 cm.
  const HeightMap tray = draw(80, 0.4, [](double x, double y) {
    const double m = std::min({x, y, 0.4 - x, 0.4 - y});
    return m < 0.01 ? 0.03 : 0.01;
  });
  RestingPlaceOptions o;
  o.probe_clearance_m = 0.01;  // wider than the lip
  Result<std::vector<RestingPlace>> t = find_resting_places(tray, o);
  ASSERT_TRUE(t.ok());
  ASSERT_EQ(t->size(), 1u);
  EXPECT_EQ(t->front().kind, RestingPlaceKind::kCavity);
  EXPECT_NEAR(t->front().depth_m, 0.02, 1e-9);

  // A dome of radius 0.2 m: only where it slopes under 30 degrees (r < 0.1 m) is a surface.
  const HeightMap dome = draw(100, 0.4, [](double x, double y) {
    const double r2 = (x - 0.2) * (x - 0.2) + (y - 0.2) * (y - 0.2);
    return r2 > 0.04 ? kNone : std::sqrt(0.04 - r2);
  });
  Result<std::vector<RestingPlace>> d = find_resting_places(dome);
  ASSERT_TRUE(d.ok());
  ASSERT_EQ(d->size(), 1u);
  EXPECT_EQ(d->front().kind, RestingPlaceKind::kSurface);
  EXPECT_NEAR(d->front().area_m2, M_PI * 0.1 * 0.1, 0.004);
  EXPECT_LT((d->front().probes.front() - Eigen::Vector2d(0.2, 0.2)).norm(), 0.01);
}

TEST(RestingPlaces, NothingToRestOnAndBadMaps) {
  // An empty map.
  Result<std::vector<RestingPlace>> empty = find_resting_places(draw(10, 1.0, [](double, double) { return kNone; }));
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());
  HeightMap bad = draw(4, 1.0, [](double, double) { return 0.5; });
  bad.z.pop_back();
  Result<std::vector<RestingPlace>> r = find_resting_places(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("15 heights for 4 x 4 cells"), std::string::npos) << r.status().to_string();
  bad = draw(4, 1.0, [](double, double) { return 0.5; });
  bad.cell_m = 0.0;
  EXPECT_FALSE(find_resting_places(bad).ok());
  bad.cell_m = 0.25;
  bad.width = 0;
  EXPECT_FALSE(find_resting_places(bad).ok());
}

}  // namespace
}  // namespace g2p
