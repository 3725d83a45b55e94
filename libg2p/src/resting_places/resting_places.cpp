// find_resting_places: a height map seen from above cut into upward-facing
// surfaces and cavities (resting_places.h). Cavities are the depressions a
// priority flood finds (water poured on the map and drained over its edge and
// down to the floor: Barnes, Lehman and Mulla 2014, "Priority-flood: an optimal
// depression-filling and watershed-labeling algorithm"); surfaces are the
// gently sloping cells above the floor, joined where neighbours meet without a
// step. Probes go to the point deepest inside each place and spread from there
// by farthest-point sampling.
#include "g2p/resting_places.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace g2p {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct Grid {
  int w, h;
  int index(int x, int y) const { return y * w + x; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < w && y < h; }
};

// The four neighbours of cell i that lie on the map.
template <typename F>
void for_each_neighbour4(const Grid& g, int i, F f) {
  const int x = i % g.w, y = i / g.w;
  if (x > 0) f(i - 1);
  if (x + 1 < g.w) f(i + 1);
  if (y > 0) f(i - g.w);
  if (y + 1 < g.h) f(i + g.w);
}

// Per cell, the level water poured on the map settles at: the lowest height
// over which a path from the cell to the map's edge or to the floor must
// climb (Priority-flood, 4-connected so that a wall drawn as a staircase of
// cells holds water).
std::vector<double> filled_levels(const Grid& g, const std::vector<double>& ground) {
  const int n = g.w * g.h;
  std::vector<double> level(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  std::vector<char> done(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    const int x = i % g.w, y = i / g.w;
    const bool edge = x == 0 || y == 0 || x + 1 == g.w || y + 1 == g.h;
    if (edge || std::isnan(ground[static_cast<std::size_t>(i)])) {
      done[static_cast<std::size_t>(i)] = 1;
      level[static_cast<std::size_t>(i)] = ground[static_cast<std::size_t>(i)];
      open.push({ground[static_cast<std::size_t>(i)], i});
    }
  }
  while (!open.empty()) {
    const double lv = open.top().first;  // not a structured binding: lambdas capture it only from C++20
    const int i = open.top().second;
    open.pop();
    for_each_neighbour4(g, i, [&](int j) {
      if (done[static_cast<std::size_t>(j)]) return;
      done[static_cast<std::size_t>(j)] = 1;
      level[static_cast<std::size_t>(j)] = std::max(ground[static_cast<std::size_t>(j)], lv);
      open.push({level[static_cast<std::size_t>(j)], j});
    });
  }
  return level;
}

// Per cell of `member` (1) its distance in cells to the nearest cell that is
// not (the map's edge counts as outside), by a two-pass chamfer (1, sqrt 2).
std::vector<double> inner_distance(const Grid& g, const std::vector<char>& member) {
  const double inf = 1e30, d1 = 1.0, d2 = std::sqrt(2.0);
  std::vector<double> d(member.size());
  for (std::size_t i = 0; i < member.size(); ++i) d[i] = member[i] ? inf : 0.0;
  auto at = [&](int x, int y) { return g.inside(x, y) ? d[static_cast<std::size_t>(g.index(x, y))] : 0.0; };
  for (int y = 0; y < g.h; ++y)
    for (int x = 0; x < g.w; ++x) {
      double& v = d[static_cast<std::size_t>(g.index(x, y))];
      if (v == 0.0) continue;
      v = std::min({v, at(x - 1, y) + d1, at(x, y - 1) + d1, at(x - 1, y - 1) + d2, at(x + 1, y - 1) + d2});
    }
  for (int y = g.h - 1; y >= 0; --y)
    for (int x = g.w - 1; x >= 0; --x) {
      double& v = d[static_cast<std::size_t>(g.index(x, y))];
      if (v == 0.0) continue;
      v = std::min({v, at(x + 1, y) + d1, at(x, y + 1) + d1, at(x + 1, y + 1) + d2, at(x - 1, y + 1) + d2});
    }
  return d;
}

// The probes of one place: its deepest-inside cell, then cells of its inner
// part, each farthest from those chosen.
std::vector<Eigen::Vector2d> place_probes(const HeightMap& map, const Grid& g, const std::vector<int>& cells,
                                          const RestingPlaceOptions& o, double& inner_radius_m) {
  std::vector<char> member(static_cast<std::size_t>(g.w * g.h), 0);
  for (int c : cells) member[static_cast<std::size_t>(c)] = 1;
  const std::vector<double> dist = inner_distance(g, member);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int c : cells) centroid += Eigen::Vector2d(c % g.w, c / g.w);
  centroid /= static_cast<double>(cells.size());
  int best = cells.front();
  for (int c : cells) {
    const double dc = dist[static_cast<std::size_t>(c)], db = dist[static_cast<std::size_t>(best)];
    const double ec = (Eigen::Vector2d(c % g.w, c / g.w) - centroid).squaredNorm();
    const double eb = (Eigen::Vector2d(best % g.w, best / g.w) - centroid).squaredNorm();
    if (dc > db + 1e-9 || (dc > db - 1e-9 && ec < eb)) best = c;
  }
  // A cell's centre lies half a cell inside the last cell step.
  const double deepest = dist[static_cast<std::size_t>(best)] - 0.5;
  inner_radius_m = deepest * map.cell_m;
  // The inner part: clear of the edge by the probe's clearance and by 40 %
  // of the deepest point's distance (a ball dropped at the very edge tests
  // the edge, not the place).
  const double clearance = std::max(o.probe_clearance_m / map.cell_m, 0.4 * deepest) + 0.5;
  std::vector<int> inner;
  for (int c : cells)
    if (dist[static_cast<std::size_t>(c)] >= clearance) inner.push_back(c);
  std::vector<int> chosen{best};
  std::vector<double> gap(inner.size(), std::numeric_limits<double>::infinity());
  while (static_cast<int>(chosen.size()) < o.probes_per_place && !inner.empty()) {
    const int last = chosen.back();
    std::size_t far = 0;
    for (std::size_t k = 0; k < inner.size(); ++k) {
      const int c = inner[k];
      gap[k] = std::min(gap[k], std::hypot(c % g.w - last % g.w, c / g.w - last / g.w));
      if (gap[k] > gap[far]) far = k;
    }
    if (gap[far] < 1.5) break;  // the inner part is covered
    chosen.push_back(inner[far]);
  }
  std::vector<Eigen::Vector2d> out;
  for (int c : chosen) out.push_back(map.centre(c % g.w, c / g.w));
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

const char* resting_place_kind_name(RestingPlaceKind kind) {
  return kind == RestingPlaceKind::kCavity ? "cavity" : "surface";
}

Result<std::vector<RestingPlace>> find_resting_places(const HeightMap& map, const RestingPlaceOptions& o) {
  if (map.width < 1 || map.height < 1 || map.width > 4096 || map.height > 4096)
    return Status::InvalidArgument("resting places: the height map must be 1 to 4096 cells a side, not " +
                                   std::to_string(map.width) + " x " + std::to_string(map.height));
  if (map.z.size() != static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height))
    return Status::InvalidArgument("resting places: the height map has " + std::to_string(map.z.size()) +
                                   " heights for " + std::to_string(map.width) + " x " + std::to_string(map.height) +
                                   " cells");
  if (!(map.cell_m > 0) || !std::isfinite(map.cell_m) || !std::isfinite(map.floor_z))
    return Status::InvalidArgument("resting places: the cell side must be positive and the floor finite");
  const Grid g{map.width, map.height};
  const int n = g.w * g.h;
  double top = -std::numeric_limits<double>::infinity();
  int covered = 0;
  for (double z : map.z)
    if (!std::isnan(z)) top = std::max(top, z), ++covered;
  std::vector<RestingPlace> places;
  if (covered == 0 || !(top > map.floor_z)) return places;
  const double height = top - map.floor_z;
  const double size = std::max(height, std::max(g.w, g.h) * map.cell_m);
  const double step = o.step_share * size;
  const double min_area = std::max(4.0, o.min_area_share * covered) * map.cell_m * map.cell_m;

  // The floor where no ray met the object; the map's edge drains too.
  std::vector<double> ground(map.z);
  for (double& z : ground)
    if (std::isnan(z)) z = map.floor_z;
  const std::vector<double> level = filled_levels(g, ground);

  // Slopes by central differences over neighbours joined without a step.
  std::vector<double> slope(static_cast<std::size_t>(n), 90.0);
  for (int i = 0; i < n; ++i) {
    if (std::isnan(map.z[static_cast<std::size_t>(i)])) continue;
    const int x = i % g.w, y = i / g.w;
    auto diff = [&](int dx, int dy) {
      double lo = map.z[static_cast<std::size_t>(i)], hi = lo, span = 0.0;
      for (int s : {-1, 1}) {
        const int xx = x + s * dx, yy = y + s * dy;
        if (!g.inside(xx, yy)) continue;
        const double z = map.z[static_cast<std::size_t>(g.index(xx, yy))];
        if (std::isnan(z) || std::abs(z - map.z[static_cast<std::size_t>(i)]) > step) continue;
        (s < 0 ? lo : hi) = z;
        span += map.cell_m;
      }
      return span > 0 ? (hi - lo) / span : 0.0;
    };
    slope[static_cast<std::size_t>(i)] = std::atan(std::hypot(diff(1, 0), diff(0, 1))) / kDegree;
  }

  const double min_depth = std::max(o.min_depth_m, o.min_depth_share * height);
  // 1: cavity cell, 2: surface cell.
  std::vector<char> type(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    const double z = map.z[static_cast<std::size_t>(i)];
    if (std::isnan(z)) continue;
    if (level[static_cast<std::size_t>(i)] - z >= min_depth)
      type[static_cast<std::size_t>(i)] = 1;
    else if (slope[static_cast<std::size_t>(i)] <= o.max_slope_deg && z - map.floor_z >= o.min_height_share * height)
      type[static_cast<std::size_t>(i)] = 2;
  }

  std::vector<int> component(static_cast<std::size_t>(n), -1);
  std::vector<RestingPlace> found[2];
  for (int seed = 0; seed < n; ++seed) {
    const char t = type[static_cast<std::size_t>(seed)];
    if (t == 0 || component[static_cast<std::size_t>(seed)] >= 0) continue;
    RestingPlace p;
    p.kind = t == 1 ? RestingPlaceKind::kCavity : RestingPlaceKind::kSurface;
    std::vector<int> stack{seed};
    component[static_cast<std::size_t>(seed)] = seed;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      p.cells.push_back(i);
      for_each_neighbour4(g, i, [&](int j) {
        if (type[static_cast<std::size_t>(j)] != t || component[static_cast<std::size_t>(j)] >= 0) return;
        // Cavity cells join across any step (a cup's bottom and its walls'
        // foot); surface cells only where the surface goes on.
        if (t == 2 && std::abs(map.z[static_cast<std::size_t>(j)] - map.z[static_cast<std::size_t>(i)]) > step) return;
        component[static_cast<std::size_t>(j)] = seed;
        stack.push_back(j);
      });
    }
    p.area_m2 = static_cast<double>(p.cells.size()) * map.cell_m * map.cell_m;
    if (p.area_m2 < min_area) continue;
    std::sort(p.cells.begin(), p.cells.end());
    std::vector<double> zs, slopes;
    double lowest = std::numeric_limits<double>::infinity(), rim = -lowest;
    for (int c : p.cells) {
      const double z = map.z[static_cast<std::size_t>(c)];
      zs.push_back(z);
      lowest = std::min(lowest, z);
      rim = std::max(rim, p.kind == RestingPlaceKind::kCavity ? level[static_cast<std::size_t>(c)] : z);
      slopes.push_back(slope[static_cast<std::size_t>(c)]);
    }
    p.z_m = median(std::move(zs));
    p.slope_deg = median(std::move(slopes));
    p.rim_z_m = rim;
    p.depth_m = p.kind == RestingPlaceKind::kCavity ? rim - lowest : 0.0;
    p.probes = place_probes(map, g, p.cells, o, p.inner_radius_m);
    if (p.inner_radius_m < o.probe_clearance_m) continue;  // too narrow for what is dropped
    found[t - 1].push_back(std::move(p));
  }
  for (int k = 0; k < 2; ++k) {
    std::vector<RestingPlace>& v = found[k];
    std::stable_sort(v.begin(), v.end(),
                     [](const RestingPlace& a, const RestingPlace& b) { return a.area_m2 > b.area_m2; });
    if (static_cast<int>(v.size()) > o.max_places) v.resize(static_cast<std::size_t>(std::max(o.max_places, 0)));
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i].name = std::string(resting_place_kind_name(v[i].kind)) + " " + std::to_string(i + 1);
      places.push_back(std::move(v[i]));
    }
  }
  return places;
}

int resting_place_at(const HeightMap& map, const std::vector<RestingPlace>& places, const Eigen::Vector3d& point,
                     double tolerance_m) {
  if (map.width < 1 || map.height < 1 || !(map.cell_m > 0)) return -1;
  const int cx = static_cast<int>(std::floor((point.x() - map.origin.x()) / map.cell_m));
  const int cy = static_cast<int>(std::floor((point.y() - map.origin.y()) / map.cell_m));
  for (std::size_t p = 0; p < places.size(); ++p) {
    const RestingPlace& place = places[p];
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= map.width || y >= map.height) continue;
        const int c = y * map.width + x;
        if (!std::binary_search(place.cells.begin(), place.cells.end(), c)) continue;
        const double z = map.z[static_cast<std::size_t>(c)];
        if (place.kind == RestingPlaceKind::kCavity ? point.z() <= place.rim_z_m + tolerance_m
                                                    : std::abs(point.z() - z) <= tolerance_m)
          return static_cast<int>(p);
      }
  }
  return -1;
}

}  // namespace g2p
