// `voxel-cut`: approximate convex decomposition by recursive axis-aligned
// cuts of a voxel grid, after V-HACD (Mamou, "Volumetric hierarchical
// approximate convex decomposition", Game Engine Gems 3, 2016).
//
// The part is voxelised and the cavities it encloses are filled; the piece whose hull exceeds it most is cut by the
// axis-aligned plane that most reduces the summed excess of the two halves,
// until every piece is within `error` of the part's volume or the hull budget
// is spent. A piece's concavity is counted on the lattice itself: the cell
// centres inside the convex hull of its occupied cells' centres, minus its
// occupied cells. A digitised convex solid has none (the hull of lattice
// points of a convex set holds no other lattice point of it), so a convex
// part is never cut. Each final piece becomes the exact hull of the part's
// surface clipped to the piece's box (plus the box corners inside the
// solid), reduced to the vertex budget.
#include <algorithm>
#include <array>
#include <cmath>
#include <queue>

#include "core/settings.h"
#include "decompose/backends.h"
#include "decompose/hull.h"
#include "decompose/voxel_grid.h"

namespace g2p {
namespace {

using detail::VoxelGrid;

struct Box {
  Eigen::Vector3i lo = Eigen::Vector3i::Zero();
  Eigen::Vector3i hi = Eigen::Vector3i::Zero();  // exclusive
  bool empty() const { return (hi.array() <= lo.array()).any(); }
};

// A piece: the cells of the grid inside `region` (a box of the partition of
// the grid), `tight` their bounding box, and its lattice concavity.
struct Piece {
  Box region;
  Box tight;
  long cells = 0;
  long excess = 0;                                    // lattice points inside the hull that are not occupied
  double depth = 0.0;                                 // the farthest of those from the part, in cells
  Eigen::Vector3i deepest = Eigen::Vector3i::Zero();  // that lattice point
};

// Occupied cells in `box`, their bounding box and the excess of their hull.
// `distance`: per cell, its distance to the part in cells.
Piece measure(const VoxelGrid& g, const std::vector<float>& distance, const Box& region) {
  Piece p;
  p.region = region;
  Eigen::Vector3i lo = region.hi, hi = region.lo;
  std::vector<double> xyz;  // lowest and highest occupied cell centre per column (enough for the hull)
  for (int j = region.lo.y(); j < region.hi.y(); ++j)
    for (int i = region.lo.x(); i < region.hi.x(); ++i) {
      int k_lo = -1, k_hi = -1;
      for (int k = region.lo.z(); k < region.hi.z(); ++k)
        if (g.at(i, j, k)) {
          if (k_lo < 0) k_lo = k;
          k_hi = k;
          ++p.cells;
        }
      if (k_lo < 0) continue;
      lo = lo.cwiseMin(Eigen::Vector3i(i, j, k_lo));
      hi = hi.cwiseMax(Eigen::Vector3i(i + 1, j + 1, k_hi + 1));
      xyz.insert(xyz.end(), {double(i), double(j), double(k_lo)});
      if (k_hi != k_lo) xyz.insert(xyz.end(), {double(i), double(j), double(k_hi)});
    }
  if (p.cells == 0) return p;
  p.tight = Box{lo, hi};
  detail::QhullHull hull;
  if (!detail::run_qhull(xyz, false, hull).ok()) {
    // One layer of cells (or a line): thicken every centre into a small cube
    // (a quarter cell each way), which adds no lattice point across the
    // layer and few within it.
    std::vector<double> thick;
    for (std::size_t c = 0; c < xyz.size(); c += 3)
      for (int n = 0; n < 8; ++n)
        thick.insert(thick.end(), {xyz[c] + ((n & 1) ? 0.25 : -0.25), xyz[c + 1] + ((n & 2) ? 0.25 : -0.25),
                                   xyz[c + 2] + ((n & 4) ? 0.25 : -0.25)});
    if (!detail::run_qhull(thick, false, hull).ok()) return p;
  }
  long lattice = 0;
  constexpr double kEps = 1e-7;
  for (int j = lo.y(); j < hi.y(); ++j)
    for (int i = lo.x(); i < hi.x(); ++i) {
      double z_lo = lo.z(), z_hi = hi.z() - 1;
      for (const Eigen::Vector4d& pl : hull.planes) {
        const double rest = -(pl[3] + pl[0] * i + pl[1] * j);  // nz * z <= rest
        if (std::abs(pl[2]) < 1e-12) {
          if (rest < -kEps) z_hi = z_lo - 1;  // the column misses the hull
        } else if (pl[2] > 0) {
          z_hi = std::min(z_hi, rest / pl[2]);
        } else {
          z_lo = std::max(z_lo, rest / pl[2]);
        }
        if (z_hi < z_lo - 1) break;
      }
      const int k0 = static_cast<int>(std::ceil(z_lo - kEps)), k1 = static_cast<int>(std::floor(z_hi + kEps));
      for (int k = k0; k <= k1; ++k) {
        ++lattice;
        if (g.at(i, j, k)) continue;
        const double d = distance[g.index(i, j, k)];
        if (d > p.depth) p.depth = d, p.deepest = Eigen::Vector3i(i, j, k);
      }
    }
  p.excess = std::max(0L, lattice - p.cells);
  return p;
}

struct Cut {
  int axis = -1;
  int at = 0;       // cell boundary index
  double cost = 0;  // the summed excess of the halves
  Piece left, right;
};

Cut try_cut(const VoxelGrid& g, const std::vector<float>& distance, const Piece& piece, int axis, int at) {
  Cut c;
  c.axis = axis;
  c.at = at;
  Box left = piece.region, right = piece.region;
  left.hi[axis] = at;
  right.lo[axis] = at;
  c.left = measure(g, distance, left);
  c.right = measure(g, distance, right);
  c.cost = static_cast<double>(c.left.excess + c.right.excess);
  return c;
}

// The best cut of a piece. Its deepest concavity (the lattice point inside
// its hull farthest from the part) is where it most needs a cut: the planes
// through that point, on the axes where it lies inside the piece, are tried
// first, as CoACD cuts through concave regions (Wei et al. 2022). A single
// cut rarely makes a hollow shallower (both halves of a bowl still span its
// middle), so these cuts are taken even when a plane elsewhere would shave
// off more hull volume at once. Otherwise: a coarse pass over `per_axis`
// evenly spaced planes per axis, then every plane between the best one's
// neighbours.
Cut best_cut(const VoxelGrid& g, const std::vector<float>& distance, const Piece& piece, int per_axis) {
  Cut best;
  for (int axis = 0; axis < 3; ++axis) {
    const int at = piece.deepest[axis];
    if (at - piece.tight.lo[axis] < 2 || piece.tight.hi[axis] - at < 2) continue;
    Cut c = try_cut(g, distance, piece, axis, at);
    if (best.axis < 0 || c.cost < best.cost) best = std::move(c);
  }
  if (best.axis >= 0) return best;
  int best_step = 1;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = piece.tight.lo[axis], b = piece.tight.hi[axis];
    if (b - a < 2) continue;
    const int step = std::max(1, (b - a) / (per_axis + 1));
    for (int at = a + step; at < b; at += step) {
      Cut c = try_cut(g, distance, piece, axis, at);
      if (best.axis < 0 || c.cost < best.cost) best = std::move(c), best_step = step;
    }
  }
  if (best.axis < 0 || best_step == 1) return best;
  const int axis = best.axis, center = best.at;
  for (int at = std::max(piece.tight.lo[axis] + 1, center - best_step + 1);
       at < std::min(piece.tight.hi[axis], center + best_step); ++at) {
    if (at == center) continue;
    Cut c = try_cut(g, distance, piece, axis, at);
    if (c.cost < best.cost) best = std::move(c);
  }
  return best;
}

// Sutherland-Hodgman: the part of a convex polygon on the side of the
// plane x[axis] >= value (sign +1) or <= value (sign -1).
void clip(std::vector<Eigen::Vector3d>& poly, int axis, double value, double sign) {
  std::vector<Eigen::Vector3d> out;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = poly[i];
    const Eigen::Vector3d& b = poly[(i + 1) % n];
    const double da = sign * (a[axis] - value), db = sign * (b[axis] - value);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  poly.swap(out);
}

// The points of a piece that lie on its cuts (the faces of its region
// inside the grid), extreme in eight directions within each cut. A hull
// reduced to a vertex budget keeps them, so that the two hulls on either
// side of a cut both cover the same octagon of its cross-section and meet
// there, rather than each retreating from the cut and leaving a crack.
std::vector<int> cross_section_corners(const std::vector<Eigen::Vector3d>& points, const std::array<double, 6>& limits,
                                       double cell_m) {
  std::vector<int> keep;
  const double tolerance = 1e-6 * cell_m;
  for (int face = 0; face < 6; ++face) {
    const double value = limits[static_cast<std::size_t>(face)];
    if (!std::isfinite(value)) continue;  // the grid's border, not a cut
    const int axis = face % 3, u = (axis + 1) % 3, v = (axis + 2) % 3;
    constexpr int kDirections[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
    for (const auto& d : kDirections) {
      int best = -1;
      double best_dot = -HUGE_VAL;
      for (std::size_t i = 0; i < points.size(); ++i) {
        const Eigen::Vector3d& q = points[i];
        if (std::abs(q[axis] - value) > tolerance) continue;
        const double dot = d[0] * q[u] + d[1] * q[v];
        if (dot > best_dot) best_dot = dot, best = static_cast<int>(i);
      }
      if (best >= 0 && std::find(keep.begin(), keep.end(), best) == keep.end()) keep.push_back(best);
    }
  }
  return keep;
}

class VoxelCutDecomposer : public Decomposer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("voxel-cut")
        .integer("resolution", resolution_, 8, 256, "cells", "grid cells along the part's longest side")
        .number("error", error_, Range::closed(0, 1), "",
                "a piece whose hull exceeds it by at most this share of the part is not cut further")
        .integer("cuts", cuts_per_axis_, 1, 64, "", "planes tried per axis in the coarse pass");
  }

  Status decompose(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) const override {
    VoxelGrid g = detail::voxelize(closed, resolution_);
    if (g.occupied.empty()) return Status::InvalidArgument("voxel-cut: the part has no extent");
    // A cavity the part closes in (the flesh inside a skin, the inside of a
    // closed bottle) is no concavity for contacts: nothing can get there.
    detail::fill_enclosed(g);
    std::vector<float> distance = detail::distance_to_occupied(g);
    for (float& d : distance) d = static_cast<float>(d / g.cell_m);
    Piece root = measure(g, distance, Box{Eigen::Vector3i::Zero(), g.size});
    if (root.cells == 0) return Status::InvalidArgument("voxel-cut: the part fills no cell");
    const double tolerance = std::max({1.0, error_ * resolution_, options.min_depth_m / g.cell_m});  // in cells

    auto worse = [](const Piece& a, const Piece& b) { return a.depth < b.depth; };
    std::priority_queue<Piece, std::vector<Piece>, decltype(worse)> open(worse);
    std::vector<Piece> leaves;
    open.push(std::move(root));
    while (!open.empty()) {
      Piece piece = open.top();
      open.pop();
      const int pieces_if_cut = static_cast<int>(leaves.size() + open.size()) + 2;
      if (piece.depth <= tolerance || pieces_if_cut > options.max_hulls) {
        leaves.push_back(std::move(piece));
        continue;
      }
      Cut cut = best_cut(g, distance, piece, cuts_per_axis_);
      if (cut.axis < 0) {
        leaves.push_back(std::move(piece));
        continue;
      }
      for (Piece* child : {&cut.left, &cut.right})
        if (child->cells > 0) open.push(std::move(*child));
    }
    if (static_cast<int>(leaves.size()) >= options.max_hulls && options.max_hulls > 1)
      out.notes.push_back("voxel-cut: stopped at the budget of " + std::to_string(options.max_hulls) +
                          " hulls (--max-hulls)");

    // Exact hulls: the surface clipped to each leaf's region. Regions on the
    // grid's border reach to infinity, so that no surface is lost to rounding.
    std::vector<std::array<double, 6>> limits;  // lo x, y, z, hi x, y, z
    for (const Piece& leaf : leaves) {
      std::array<double, 6> l{};
      for (int a = 0; a < 3; ++a) {
        l[a] = leaf.region.lo[a] <= 0 ? -HUGE_VAL : g.origin[a] + g.cell_m * leaf.region.lo[a];
        l[3 + a] = leaf.region.hi[a] >= g.size[a] ? HUGE_VAL : g.origin[a] + g.cell_m * leaf.region.hi[a];
      }
      limits.push_back(l);
    }
    std::vector<std::vector<Eigen::Vector3d>> points(leaves.size());
    std::vector<Eigen::Vector3d> poly;
    for (const Eigen::Vector3i& t : closed.triangles) {
      std::array<Eigen::Vector3d, 3> v;
      for (int k = 0; k < 3; ++k)
        v[static_cast<std::size_t>(k)] = closed.positions[static_cast<std::size_t>(t[k])].cast<double>();
      const Eigen::Vector3d lo = v[0].cwiseMin(v[1]).cwiseMin(v[2]), hi = v[0].cwiseMax(v[1]).cwiseMax(v[2]);
      for (std::size_t L = 0; L < leaves.size(); ++L) {
        const std::array<double, 6>& l = limits[L];
        if (hi.x() < l[0] || hi.y() < l[1] || hi.z() < l[2] || lo.x() > l[3] || lo.y() > l[4] || lo.z() > l[5])
          continue;
        poly.assign(v.begin(), v.end());
        for (int a = 0; a < 3 && !poly.empty(); ++a) {
          if (lo[a] < l[a]) clip(poly, a, l[a], 1.0);
          if (!poly.empty() && hi[a] > l[3 + a]) clip(poly, a, l[3 + a], -1.0);
        }
        points[L].insert(points[L].end(), poly.begin(), poly.end());
      }
    }
    // Corners of a region inside the solid bound its cross-sections too.
    for (std::size_t L = 0; L < leaves.size(); ++L) {
      const Box& r = leaves[L].region;
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector3i corner((c & 1) ? r.hi.x() : r.lo.x(), (c & 2) ? r.hi.y() : r.lo.y(),
                                     (c & 4) ? r.hi.z() : r.lo.z());
        bool inside = true;  // all eight cells around the lattice vertex occupied
        for (int n = 0; n < 8 && inside; ++n) {
          const Eigen::Vector3i cell = corner - Eigen::Vector3i(n & 1, (n >> 1) & 1, (n >> 2) & 1);
          inside =
              (cell.array() >= 0).all() && (cell.array() < g.size.array()).all() && g.at(cell.x(), cell.y(), cell.z());
        }
        if (inside) points[L].push_back(g.origin + g.cell_m * corner.cast<double>());
      }
    }
    int flat = 0;
    for (std::size_t L = 0; L < leaves.size(); ++L) {
      std::vector<Eigen::Vector3d>& p = points[L];
      if (p.empty()) continue;
      Result<Mesh> hull =
          detail::convex_hull_keeping(p, options.max_vertices_per_hull, cross_section_corners(p, limits[L], g.cell_m));
      if (!hull.ok()) {
        // A sliver on one plane: give it half a cell of thickness each way
        // along the axis it is thinnest in.
        Eigen::AlignedBox3d box;
        for (const Eigen::Vector3d& q : p) box.extend(q);
        int axis = 0;
        box.sizes().minCoeff(&axis);
        const std::size_t n = p.size();
        for (std::size_t i = 0; i < n; ++i) {
          Eigen::Vector3d q = p[i];
          q[axis] += 0.5 * g.cell_m;
          p.push_back(q);
          p[i][axis] -= 0.5 * g.cell_m;
        }
        hull = convex_hull(p, options.max_vertices_per_hull);
        ++flat;
      }
      if (!hull.ok()) continue;
      out.hulls.push_back(std::move(*hull));
    }
    if (flat > 0)
      out.notes.push_back("voxel-cut: " + std::to_string(flat) + " flat piece(s) given half a grid cell (" +
                          std::to_string(g.cell_m) + " m) of thickness");
    if (out.hulls.empty()) return Status::InvalidArgument("voxel-cut: no piece spans a volume");
    return Status::Ok();
  }

 private:
  int resolution_ = 64;     // grid cells along the part's longest side
  double error_ = 0.02;     // stop cutting a piece whose hull exceeds it by at most this share of the part
  int cuts_per_axis_ = 10;  // planes tried per axis in the coarse pass
};

}  // namespace

std::unique_ptr<Decomposer> make_voxel_cut_decomposer() { return std::make_unique<VoxelCutDecomposer>(); }

}  // namespace g2p
