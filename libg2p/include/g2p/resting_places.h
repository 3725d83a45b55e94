// Resting places: where things put on an object can stay. A height map of
// the object seen from straight above (what a falling ball meets first) is
// cut into upward-facing surfaces (a seat, a table top, a shelf) and cavities
// (the inside of a cup, a bowl, a pot), and each gets the points to drop
// probes at. The contact check (export.h, check_contacts_in_mujoco) drops
// balls there and reports per place how many stayed ("seat: 9 of 9 balls at
// rest"); the analysis itself needs no physics engine.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// Heights seen from above on a regular grid over x, y (object frame, +Z up).
struct HeightMap {
  int width = 0;                                     // cells along x
  int height = 0;                                    // cells along y
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // x, y of cell (0, 0)'s lower corner, m
  double cell_m = 0.0;                               // side of a square cell, m
  double floor_z = 0.0;                              // the floor's height, m (below the object)
  // Row-major (row y, column x): the height of the first surface a ray
  // straight down through the cell's centre meets, m; NaN where it meets
  // nothing of the object (the floor).
  std::vector<double> z;

  Eigen::Vector2d centre(int x, int y) const { return origin + cell_m * Eigen::Vector2d(x + 0.5, y + 0.5); }
};

enum class RestingPlaceKind {
  kSurface,  // an upward-facing surface a thing can lie on (a seat, a table top)
  kCavity,   // a hollow walled on every side (a cup's inside, a bowl)
};
G2P_API const char* resting_place_kind_name(RestingPlaceKind kind);  // "surface", "cavity"

struct RestingPlace {
  RestingPlaceKind kind = RestingPlaceKind::kSurface;
  std::string name;        // "surface 1", "cavity 1": by kind, largest first
  std::vector<int> cells;  // HeightMap cell indices (y * width + x)
  double area_m2 = 0.0;
  double z_m = 0.0;             // median height of its cells, m
  double depth_m = 0.0;         // cavity: from its lowest cell to the rim that walls it in, m; surface: 0
  double rim_z_m = 0.0;         // cavity: the height at which it would spill over, m; surface: its highest cell
  double slope_deg = 0.0;       // median slope of its cells (central differences), degrees
  double inner_radius_m = 0.0;  // distance from the point deepest inside it to its edge, m
  // Where to drop probes over it (x, y in the object's frame, m): the point
  // deepest inside it first, then points spread over its inner part.
  std::vector<Eigen::Vector2d> probes;
};

struct RestingPlaceOptions {
  double max_slope_deg = 30.0;    // a surface cell slopes at most this much
  double min_depth_m = 0.01;      // a cavity is at least this deep (and min_depth_share of the object)
  double min_depth_share = 0.05;  // ... as a share of the object's height above the floor
  double min_height_share = 0.1;  // a surface lies this share of the object's height above the floor
  double min_area_share = 0.02;   // a place covers at least this share of the object's top view
  double step_share = 0.02;       // neighbours more than this share of the object's size apart in z are not joined
  // Probes at least this far inside the place's edge (a ball's radius, say);
  // a place narrower than that is left out.
  double probe_clearance_m = 0.0;
  int probes_per_place = 9;  // the deepest-inside point and up to this many less one more
  int max_places = 6;        // of each kind, largest first
};

// The resting places of `map`, cavities first, each kind largest first.
// An error names a malformed map (sizes, a cell side that is not positive).
G2P_API Result<std::vector<RestingPlace>> find_resting_places(const HeightMap& map,
                                                              const RestingPlaceOptions& options = {});

// The place whose cells (grown by one cell) hold x, y and whose height
// matches: a cavity holds what lies below its rim, a surface what lies within
// `tolerance_m` of its cells' height. -1: none.
G2P_API int resting_place_at(const HeightMap& map, const std::vector<RestingPlace>& places,
                             const Eigen::Vector3d& point, double tolerance_m);

}  // namespace g2p
