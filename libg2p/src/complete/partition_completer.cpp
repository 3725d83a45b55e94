// The `partition` completer: the whole object closed once on a grid, its
// interior split among the parts by nearest labelled surface, and every
// part's closed surface extracted as a level set.
//
// 1. Distances. On a regular grid sized from the object (finer where a part
//    is thin and stick-like), the exact distance to the nearest triangle at
//    every grid point within one cell of the surface, then everywhere by a
//    separable exact Euclidean distance transform of those samples
//    (Felzenszwalb & Huttenlocher 2012, "Distance transforms of sampled
//    functions") that also carries the nearest sample's part: the interior
//    goes to the nearest labelled surface.
// 2. Inside and outside. The outside is flooded from the grid's border
//    through points farther than `gap` cells from the surface, then grown
//    back by `gap` cells (a morphological closing with a ball): holes and
//    cracks narrower than about twice the gap do not leak, and nothing inside
//    depends on normals or on the mesh being closed. Open sheets the closing
//    cannot see (a grid edge crosses the surface but both ends are outside)
//    keep a thin slab so no part vanishes.
// 3. Surfaces. Each part's field is the object's signed distance cut by the
//    part's region; its zero level set is extracted by marching tetrahedra
//    (six Kuhn tetrahedra per cell), which always gives a closed 2-manifold,
//    placed between grid points by the distances, so flat faces land where
//    they are, not on the grid.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include "complete/backends.h"
#include "complete/geometry.h"
#include "core/distance_transform.h"
#include "core/segment_tester.h"
#include "core/settings.h"
#include "core/simplify.h"

namespace g2p {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double h = 1.0;  // cell size, metres
  int nx = 0, ny = 0, nz = 0;
  std::size_t size() const { return static_cast<std::size_t>(nx) * ny * nz; }
  std::size_t at(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k);
  }
  Eigen::Vector3d point(int i, int j, int k) const { return origin + h * Eigen::Vector3d(i, j, k); }
  Eigen::Vector3i coords(std::size_t a) const {  // the inverse of at()
    return Eigen::Vector3i(static_cast<int>(a % static_cast<std::size_t>(nx)),
                           static_cast<int>((a / static_cast<std::size_t>(nx)) % static_cast<std::size_t>(ny)),
                           static_cast<int>(a / (static_cast<std::size_t>(nx) * ny)));
  }
  int dim(int axis) const { return axis == 0 ? nx : axis == 1 ? ny : nz; }
  std::size_t stride(int axis) const {  // from a point to its neighbour along `axis`
    return axis == 0 ? 1 : axis == 1 ? static_cast<std::size_t>(nx) : static_cast<std::size_t>(nx) * ny;
  }
};

// In place: f (squared distance in cells^2, infinity where no sample) becomes
// the squared distance to the nearest sample plus its value; `label`, if
// given, the nearest sample's label (core/distance_transform.h).
void distance_transform(const Grid& g, std::vector<float>& f, std::vector<int>* label) {
  detail::squared_distance_transform<float>({g.nx, g.ny, g.nz}, f, label);
}

void atomic_min(std::uint64_t* target, std::uint64_t value) {
  std::uint64_t current = __atomic_load_n(target, __ATOMIC_RELAXED);
  while (value < current &&
         !__atomic_compare_exchange_n(target, &current, value, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
  }
}

// Marching tetrahedra over cells [lo, hi) of the grid, field value(index) in
// cells (negative inside, never zero). Every edge of the Kuhn triangulation
// runs from a corner to one with larger coordinates, so its vertex is kept
// under the lower corner in one of two z-layers of seven edge slots.
template <typename Field>
Mesh extract_surface(const Grid& g, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, Field value) {
  static constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                      {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  Mesh mesh;
  const int sx = hi.x() - lo.x() + 1, sy = hi.y() - lo.y() + 1;
  const std::size_t layer = static_cast<std::size_t>(sx) * sy * 7;
  std::vector<int> slots[2] = {std::vector<int>(layer, -1), std::vector<int>(layer, -1)};
  std::size_t idx[8];
  float val[8];
  Eigen::Vector3d pos[8];
  for (int k = lo.z(); k < hi.z(); ++k) {
    std::vector<int>& below = slots[(k - lo.z()) & 1];
    std::vector<int>& above = slots[(k - lo.z() + 1) & 1];
    std::fill(above.begin(), above.end(), -1);
    for (int j = lo.y(); j < hi.y(); ++j)
      for (int i = lo.x(); i < hi.x(); ++i) {
        bool any_in = false, any_out = false;
        for (int c = 0; c < 8; ++c) {
          idx[c] = g.at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          val[c] = value(idx[c]);
          (val[c] < 0 ? any_in : any_out) = true;
        }
        if (!any_in || !any_out) continue;
        for (int c = 0; c < 8; ++c) pos[c] = g.point(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
        auto edge_vertex = [&](int ca, int cb) {
          if ((ca & cb) != ca) std::swap(ca, cb);  // ca: the lower corner (its bits are a subset of cb's)
          const int dir = (cb ^ ca) - 1;           // 0..6, which of the seven directions
          std::vector<int>& slab = (ca & 4) ? above : below;
          const std::size_t slot =
              (static_cast<std::size_t>(j + ((ca >> 1) & 1) - lo.y()) * sx + (i + (ca & 1) - lo.x())) * 7 + dir;
          int& v = slab[slot];
          if (v < 0) {
            v = mesh.num_vertices();
            const double t = val[ca] / (static_cast<double>(val[ca]) - val[cb]);
            mesh.positions.push_back((pos[ca] + t * (pos[cb] - pos[ca])).cast<float>());
          }
          return v;
        };
        for (const auto& tet : kTets) {
          int in[4], out[4], ni = 0, no = 0;
          for (int c : tet) (val[c] < 0 ? in[ni++] : out[no++]) = c;
          if (ni == 0 || no == 0) continue;
          // Outward = from the inside corners towards the outside ones.
          Eigen::Vector3d dir = Eigen::Vector3d::Zero();
          for (int x = 0; x < no; ++x) dir += pos[out[x]] / no;
          for (int x = 0; x < ni; ++x) dir -= pos[in[x]] / ni;
          auto emit = [&](int v0, int v1, int v2) {
            const Eigen::Vector3d p0 = mesh.positions[static_cast<std::size_t>(v0)].cast<double>();
            const Eigen::Vector3d nrm = (mesh.positions[static_cast<std::size_t>(v1)].cast<double>() - p0)
                                            .cross(mesh.positions[static_cast<std::size_t>(v2)].cast<double>() - p0);
            if (nrm.dot(dir) < 0) std::swap(v1, v2);
            mesh.triangles.emplace_back(v0, v1, v2);
          };
          if (ni == 1 || no == 1) {
            const int apex = ni == 1 ? in[0] : out[0];
            const int* others = ni == 1 ? out : in;
            emit(edge_vertex(apex, others[0]), edge_vertex(apex, others[1]), edge_vertex(apex, others[2]));
          } else {
            const int a0 = edge_vertex(in[0], out[0]), a1 = edge_vertex(in[0], out[1]);
            const int b0 = edge_vertex(in[1], out[0]), b1 = edge_vertex(in[1], out[1]);
            // Quad a0-a1-b1-b0 (around the tetrahedron's middle section).
            emit(a0, a1, b1);
            emit(a0, b1, b0);
          }
        }
      }
  }
  return mesh;
}

double signed_volume(const Mesh& mesh) {
  double six_v = 0.0;
  for (const auto& t : mesh.triangles)
    six_v += mesh.positions[static_cast<std::size_t>(t[0])].cast<double>().dot(
        mesh.positions[static_cast<std::size_t>(t[1])].cast<double>().cross(
            mesh.positions[static_cast<std::size_t>(t[2])].cast<double>()));
  return six_v / 6.0;
}

// Where a grid point lies (step 2).
enum PointState : std::uint8_t {
  kInside = 0,
  kOutside = 1,
  kSlab = 2,  // kept as a slab of an open sheet
};

// The part of every face (-1 for none); an error names a face that is out of
// range or in two parts.
Result<std::vector<int>> face_parts(const Mesh& mesh, const std::vector<Part>& parts) {
  const int nf = mesh.num_faces(), np = static_cast<int>(parts.size());
  if (nf == 0) return Status::InvalidArgument("partition: the mesh has no triangles");
  if (np == 0) return Status::InvalidArgument("partition: no parts to complete");
  std::vector<int> face_part(static_cast<std::size_t>(nf), -1);
  for (int p = 0; p < np; ++p)
    for (int f : parts[static_cast<std::size_t>(p)].faces) {
      if (f < 0 || f >= nf)
        return Status::InvalidArgument("partition: part " + std::to_string(p) + " lists face " + std::to_string(f) +
                                       ", but the mesh has " + std::to_string(nf));
      int& fp = face_part[static_cast<std::size_t>(f)];
      if (fp >= 0 && fp != p)
        return Status::InvalidArgument("partition: face " + std::to_string(f) + " is in parts " + std::to_string(fp) +
                                       " and " + std::to_string(p));
      fp = p;
    }
  return face_part;
}

// The grid the object is closed on.
struct GridChoice {
  Grid grid;
  // The cell size every step measures in, metres. It is grid.h except when
  // max_cells could not be met in 64 attempts: then grid.h (and the point
  // counts) are the last attempt's and this the next, larger one.
  double h = 1.0;
  int thin_part = -1;  // the part that refined the grid, -1 if none did
  int gap = 2;         // closing radius, cells: the setting, or wider for CompletionInput::thin_thickness_m
  bool widened = false;
};

std::string grid_note(const GridChoice& choice) {
  const Grid& g = choice.grid;
  std::ostringstream note;
  note.precision(3);
  note << "grid " << g.nx << "x" << g.ny << "x" << g.nz << " points, cell " << choice.h * 1000 << " mm";
  if (choice.thin_part >= 0) note << " (refined for thin part " << choice.thin_part << ")";
  if (choice.widened) note << ", closing radius " << choice.gap << " cells for a wall this thin";
  return note.str();
}

// Exact distances near the surface: for every triangle, the grid
// points in its bounding box grown by one cell get the exact distance to it;
// each point within one cell keeps the nearest.
struct SurfaceBand {
  std::vector<float> dist2;  // squared distance, cells^2; infinity farther than a cell
  std::vector<int> nearest;  // the nearest triangle; -1 farther than a cell
};

SurfaceBand exact_distances_near_surface(const Mesh& mesh, const Grid& g, double h) {
  const std::size_t n = g.size();
  // Squared distance (its float bits, which order like the floats) over the
  // triangle, so one atomic minimum keeps both and ties go to the lower index.
  std::vector<std::uint64_t> best(n, ~std::uint64_t{0});
  tbb::parallel_for(tbb::blocked_range<int>(0, mesh.num_faces(), 2048), [&](const tbb::blocked_range<int>& r) {
    for (int t = r.begin(); t != r.end(); ++t) {
      const Eigen::Vector3i& tri = mesh.triangles[static_cast<std::size_t>(t)];
      const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(tri[0])].cast<double>();
      const Eigen::Vector3d b = mesh.positions[static_cast<std::size_t>(tri[1])].cast<double>();
      const Eigen::Vector3d c = mesh.positions[static_cast<std::size_t>(tri[2])].cast<double>();
      const Eigen::Vector3d lo = (a.cwiseMin(b).cwiseMin(c) - g.origin) / h - Eigen::Vector3d::Ones();
      const Eigen::Vector3d hi = (a.cwiseMax(b).cwiseMax(c) - g.origin) / h + Eigen::Vector3d::Ones();
      const int i0 = std::max(0, static_cast<int>(std::ceil(lo.x()))),
                i1 = std::min(g.nx - 1, static_cast<int>(hi.x()));
      const int j0 = std::max(0, static_cast<int>(std::ceil(lo.y()))),
                j1 = std::min(g.ny - 1, static_cast<int>(hi.y()));
      const int k0 = std::max(0, static_cast<int>(std::ceil(lo.z()))),
                k1 = std::min(g.nz - 1, static_cast<int>(hi.z()));
      for (int k = k0; k <= k1; ++k)
        for (int j = j0; j <= j1; ++j)
          for (int i = i0; i <= i1; ++i) {
            const Eigen::Vector3d p = g.point(i, j, k);
            const float d2 =
                static_cast<float>((detail::closest_point_on_triangle(p, a, b, c) - p).squaredNorm() / (h * h));
            if (d2 > 1.0f) continue;
            std::uint32_t bits;
            std::memcpy(&bits, &d2, sizeof bits);
            atomic_min(&best[g.at(i, j, k)], (static_cast<std::uint64_t>(bits) << 32) | static_cast<std::uint32_t>(t));
          }
    }
  });
  SurfaceBand band{std::vector<float>(n, kInf), std::vector<int>(n, -1)};
  for (std::size_t i = 0; i < n; ++i) {
    if (best[i] == ~std::uint64_t{0}) continue;
    const auto bits = static_cast<std::uint32_t>(best[i] >> 32);
    std::memcpy(&band.dist2[i], &bits, sizeof bits);
    band.nearest[i] = static_cast<int>(best[i] & 0xffffffffu);
  }
  return band;
}

// The flood of the closing: 0 at every point reached from the grid's border through
// points whose squared distance `dist2` exceeds `core_d2`, infinity elsewhere.
std::vector<float> flood_from_border(const Grid& g, const std::vector<float>& dist2, float core_d2) {
  std::vector<float> to_core(g.size(), kInf);
  std::vector<std::size_t> queue;
  auto push = [&](std::size_t i) {
    if (to_core[i] == 0.0f || !(dist2[i] > core_d2)) return;
    to_core[i] = 0.0f;
    queue.push_back(i);
  };
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        if (i == 0 || j == 0 || k == 0 || i == g.nx - 1 || j == g.ny - 1 || k == g.nz - 1) push(g.at(i, j, k));
  const std::size_t sx = 1, sy = static_cast<std::size_t>(g.nx), sz = sy * g.ny;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t i = queue[head];
    const std::size_t x = i % sy, y = (i / sy) % static_cast<std::size_t>(g.ny), z = i / sz;
    if (x > 0) push(i - sx);
    if (x + 1 < sy) push(i + sx);
    if (y > 0) push(i - sy);
    if (y + 1 < static_cast<std::size_t>(g.ny)) push(i + sy);
    if (z > 0) push(i - sz);
    if (z + 1 < static_cast<std::size_t>(g.nz)) push(i + sz);
  }
  return to_core;
}

// Inside and outside by closing: the outside flooded from the border
// through points farther than `gap` cells from the surface, then grown back by
// `gap` cells (a morphological closing with a ball). `dist2` is the squared
// distance to the surface everywhere, cells^2. Every point is kInside or kOutside.
std::vector<std::uint8_t> inside_outside_by_closing(const Grid& g, const std::vector<float>& dist2, int gap) {
  const float core_d2 = static_cast<float>(gap) * gap;
  std::vector<float> to_core = flood_from_border(g, dist2, core_d2);
  distance_transform(g, to_core, nullptr);  // grow the flooded core back by `gap` cells
  std::vector<std::uint8_t> state(g.size(), kInside);
  for (std::size_t i = 0; i < state.size(); ++i) state[i] = to_core[i] <= core_d2 + 1e-3f ? kOutside : kInside;
  return state;
}

// The grid points within one cell of the surface, in index order.
std::vector<std::size_t> near_surface_points(const std::vector<int>& nearest) {
  std::vector<std::size_t> near_surface;
  for (std::size_t i = 0; i < nearest.size(); ++i)
    if (nearest[i] >= 0) near_surface.push_back(i);
  return near_surface;
}

// Near-surface correction: the closing leaves a thin layer of outside
// points next to the surface marked inside where its ball, centred on grid
// points, cannot reach (up to about half a cell on curved or slanted faces). A
// point within a cell of the surface that sees an outside neighbour without
// crossing the surface is outside too; two rounds, so the fix stays next to
// where the closing decided and cannot leak through the gaps it sealed.
void correct_near_surface(const Grid& g, double h, const detail::SegmentTester& segments,
                          const std::vector<std::size_t>& near_surface, std::vector<std::uint8_t>& state) {
  for (int round = 0; round < 2; ++round) {
    std::vector<std::uint8_t> flip(near_surface.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, near_surface.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t x = r.begin(); x != r.end(); ++x) {
                          const std::size_t a = near_surface[x];
                          if (state[a] != kInside) continue;
                          const Eigen::Vector3i c = g.coords(a);
                          const Eigen::Vector3d pa = g.point(c.x(), c.y(), c.z());
                          for (int axis = 0; axis < 3 && !flip[x]; ++axis)
                            for (int side : {-1, 1}) {
                              if (c[axis] + side < 0 || c[axis] + side >= g.dim(axis)) continue;
                              const std::size_t b = side > 0 ? a + g.stride(axis) : a - g.stride(axis);
                              if (state[b] != kOutside) continue;
                              if (!segments.crosses(pa, pa + side * h * Eigen::Vector3d::Unit(axis))) {
                                flip[x] = 1;
                                break;
                              }
                            }
                        }
                      });
    for (std::size_t x = 0; x < near_surface.size(); ++x)
      if (flip[x]) state[near_surface[x]] = kOutside;
  }
}

// Open sheets: the closing cannot see a sheet with outside on both
// sides (a grid edge crosses the surface but both its ends are outside); the
// nearer end of each such edge is kept as a slab. Returns how many points.
int keep_open_sheets(const Grid& g, double h, const detail::SegmentTester& segments,
                     const std::vector<std::size_t>& near_surface, const std::vector<float>& dist2,
                     const std::vector<int>& nearest, std::vector<std::uint8_t>& state) {
  int sheet_points = 0;
  for (std::size_t a : near_surface) {
    if (state[a] == kInside) continue;
    const Eigen::Vector3i c = g.coords(a);
    for (int axis = 0; axis < 3; ++axis) {
      if (c[axis] + 1 >= g.dim(axis)) continue;
      const std::size_t b = a + g.stride(axis);
      if (state[b] == kInside || nearest[b] < 0) continue;
      const Eigen::Vector3d pa = g.point(c.x(), c.y(), c.z());
      if (!segments.crosses(pa, pa + h * Eigen::Vector3d::Unit(axis))) continue;
      const std::size_t keep = dist2[a] <= dist2[b] ? a : b;
      if (state[keep] != kSlab) ++sheet_points;
      state[keep] = kSlab;
    }
  }
  return sheet_points;
}

// Interior labels from the skin: the interior goes to the part of the
// nearest surface on the object's skin, the grid points within a cell of the
// surface where inside meets outside. Surfaces with inside on both sides (the
// coincident faces of two touching boxes, hidden inner walls) do not claim
// volume. Returns every grid point's part (-1 for none).
std::vector<int> interior_labels_from_skin(const Grid& g, const std::vector<std::uint8_t>& state,
                                           const SurfaceBand& band, const std::vector<int>& face_part) {
  std::vector<float> seed(g.size(), kInf);
  std::vector<int> label(g.size(), -1);
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t a = g.at(i, j, k);
        if (band.nearest[a] < 0) continue;
        const int coord[3] = {i, j, k};
        const bool out_a = state[a] == kOutside;
        bool skin = false;
        for (int axis = 0; axis < 3 && !skin; ++axis) {
          if (coord[axis] > 0) skin |= (state[a - g.stride(axis)] == kOutside) != out_a;
          if (coord[axis] + 1 < g.dim(axis)) skin |= (state[a + g.stride(axis)] == kOutside) != out_a;
        }
        if (!skin) continue;
        const int part = face_part[static_cast<std::size_t>(band.nearest[a])];
        if (part < 0) continue;  // a kept part's face: its solid is its own (give_kept_solids)
        seed[a] = band.dist2[a];
        label[a] = part;
      }
  distance_transform(g, seed, &label);
  return label;
}

// The object's signed field in cells, positive outside, negative
// inside, -0.25 at slab points; never exactly zero so no vertex sits on a grid point.
// Every grid point inside a kept part's closed surface goes to that part:
// crossings along the grid's x lines (nudged off the grid by 1e-4 of a cell
// so that they miss the edges of faces lying on grid planes), paired by
// parity (a kept surface bounds a solid, cavities wound inward).
void give_kept_solids(const Grid& g, const CompletionInput& input, std::vector<int>& label) {
  const double nudge = 1e-4 * g.h;
  for (std::size_t p = 0; p < input.parts->size(); ++p) {
    if (!input.is_kept(p)) continue;
    const Mesh& solid = (*input.kept)[p];
    const Eigen::AlignedBox3d box = bounds(solid);
    auto line_range = [&](int axis, int& lo, int& hi) {
      lo = std::max(0, static_cast<int>(std::ceil((box.min()[axis] - g.origin[axis] - nudge) / g.h)));
      hi = std::min(g.dim(axis) - 1, static_cast<int>(std::floor((box.max()[axis] - g.origin[axis] - nudge) / g.h)));
    };
    int j0, j1, k0, k1;
    line_range(1, j0, j1);
    line_range(2, k0, k1);
    if (j1 < j0 || k1 < k0) continue;
    const int nj = j1 - j0 + 1;
    std::vector<std::vector<double>> crossings(static_cast<std::size_t>(nj) * (k1 - k0 + 1));
    for (const Eigen::Vector3i& t : solid.triangles) {
      const Eigen::Vector3d a = solid.positions[static_cast<std::size_t>(t[0])].cast<double>();
      const Eigen::Vector3d b = solid.positions[static_cast<std::size_t>(t[1])].cast<double>();
      const Eigen::Vector3d c = solid.positions[static_cast<std::size_t>(t[2])].cast<double>();
      const double area = (b.y() - a.y()) * (c.z() - a.z()) - (b.z() - a.z()) * (c.y() - a.y());
      if (area == 0.0) continue;
      const int tj0 =
          std::max(j0, static_cast<int>(std::ceil((std::min({a.y(), b.y(), c.y()}) - g.origin.y() - nudge) / g.h)));
      const int tj1 =
          std::min(j1, static_cast<int>(std::floor((std::max({a.y(), b.y(), c.y()}) - g.origin.y() - nudge) / g.h)));
      const int tk0 =
          std::max(k0, static_cast<int>(std::ceil((std::min({a.z(), b.z(), c.z()}) - g.origin.z() - nudge) / g.h)));
      const int tk1 =
          std::min(k1, static_cast<int>(std::floor((std::max({a.z(), b.z(), c.z()}) - g.origin.z() - nudge) / g.h)));
      for (int k = tk0; k <= tk1; ++k)
        for (int j = tj0; j <= tj1; ++j) {
          const double y = g.origin.y() + j * g.h + nudge, z = g.origin.z() + k * g.h + nudge;
          auto edge = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
            return (v.y() - u.y()) * (z - u.z()) - (v.z() - u.z()) * (y - u.y());
          };
          const double w0 = edge(b, c), w1 = edge(c, a), w2 = edge(a, b);
          const bool inside = area > 0 ? (w0 >= 0 && w1 >= 0 && w2 >= 0) : (w0 <= 0 && w1 <= 0 && w2 <= 0);
          if (!inside) continue;
          crossings[static_cast<std::size_t>(k - k0) * nj + (j - j0)].push_back(
              a.x() + (w1 * (b.x() - a.x()) + w2 * (c.x() - a.x())) / area);
        }
    }
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        std::vector<double>& x = crossings[static_cast<std::size_t>(k - k0) * nj + (j - j0)];
        if (x.size() < 2 || x.size() % 2 != 0) continue;
        std::sort(x.begin(), x.end());
        for (std::size_t m = 0; m + 1 < x.size(); m += 2) {
          const int i0 = std::max(0, static_cast<int>(std::ceil((x[m] - g.origin.x()) / g.h)));
          const int i1 = std::min(g.nx - 1, static_cast<int>(std::floor((x[m + 1] - g.origin.x()) / g.h)));
          for (int i = i0; i <= i1; ++i) label[g.at(i, j, k)] = static_cast<int>(p);
        }
      }
  }
}

std::vector<float> signed_field(const std::vector<float>& dist2, const std::vector<std::uint8_t>& state) {
  constexpr float kMinMagnitude = 0.02f;
  std::vector<float> field(dist2.size());
  for (std::size_t i = 0; i < field.size(); ++i) {
    const float d = std::max(std::sqrt(dist2[i]), kMinMagnitude);
    field[i] = state[i] == kOutside ? d : state[i] == kSlab ? -0.25f : -d;
  }
  return field;
}

// The box of inside grid points each part owns; hi.x() < 0 for a part that
// owns none (smaller than a cell).
struct PartBoxes {
  std::vector<Eigen::Vector3i> lo, hi;
};

PartBoxes part_boxes(const Grid& g, const std::vector<float>& field, const std::vector<int>& label, int np) {
  PartBoxes boxes{std::vector<Eigen::Vector3i>(static_cast<std::size_t>(np),
                                               Eigen::Vector3i::Constant(std::numeric_limits<int>::max())),
                  std::vector<Eigen::Vector3i>(static_cast<std::size_t>(np), Eigen::Vector3i::Constant(-1))};
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t x = g.at(i, j, k);
        const int p = label[x];
        if (field[x] >= 0 || p < 0) continue;
        auto& lo = boxes.lo[static_cast<std::size_t>(p)];
        auto& hi = boxes.hi[static_cast<std::size_t>(p)];
        lo = lo.cwiseMin(Eigen::Vector3i(i, j, k));
        hi = hi.cwiseMax(Eigen::Vector3i(i, j, k));
      }
  return boxes;
}

// Part p's surface: the object's field cut by the part's region, extracted
// within the part's box grown by a point.
Mesh part_surface(const Grid& g, const std::vector<float>& field, const std::vector<int>& label, const PartBoxes& boxes,
                  int p) {
  const Eigen::Vector3i all_hi(g.nx - 1, g.ny - 1, g.nz - 1);
  const Eigen::Vector3i lo = (boxes.lo[static_cast<std::size_t>(p)] - Eigen::Vector3i::Ones()).cwiseMax(0);
  const Eigen::Vector3i hi = (boxes.hi[static_cast<std::size_t>(p)] + Eigen::Vector3i::Ones()).cwiseMin(all_hi);
  return extract_surface(g, lo, hi, [&](std::size_t i) {
    const float f = field[i];
    if (f >= 0) return f;
    return std::max(f, label[i] == p ? -0.5f : 0.5f);
  });
}

// A patch as a part of its own: every face of `patch`, with `part`'s label and area.
Part whole_patch_part(const Mesh& patch, const Part& part) {
  std::vector<int> faces(static_cast<std::size_t>(patch.num_faces()));
  for (int i = 0; i < patch.num_faces(); ++i) faces[static_cast<std::size_t>(i)] = i;
  return Part{part.label, std::move(faces), part.area_m2};
}

class PartitionCompleter final : public Completer {
 public:
  SettingsSpec settings() override {
    return SettingsSpec("partition")
        .number("resolution", resolution_, Range::closed(8, 2048), "cells", "cells along the object's longest side")
        .number("max_resolution", max_resolution_, Range::closed(8, 2048), "cells",
                "the finest grid thin parts may ask for, along the longest side")
        .number("min_cells_across", min_cells_across_, Range::closed(0, 64), "cells",
                "a stick-like part's second-largest extent spans at least this many cells")
        .number("simplify", simplify_, Range::closed(0, 1), "cells",
                "largest surface change of the simplification (0 keeps every triangle)")
        .integer("simplify_max_triangles", simplify_max_triangles_, 0, 1000000000, "",
                 "larger surfaces are not simplified")
        .number("refine_min_area_fraction", refine_min_area_fraction_, Range::closed(0, 1), "",
                "parts with less of the total area do not refine the grid")
        .integer("gap", gap_, 1, 16, "cells", "closing radius")
        .number("max_cells", max_cells_, Range::closed(1e3, 1e9), "", "memory guard: grid points (about 30 bytes each)")
        .number("max_relative_distance", max_relative_distance_, Range::above(0), "",
                "a part whose surface strays farther from its patch (x the patch's diagonal) fails")
        .or_word("off", std::numeric_limits<double>::infinity());
  }

  Result<Completion> complete(const CompletionInput& input) const override;

 private:
  Result<GridChoice> size_grid(const Mesh& mesh, const std::vector<Part>& parts, const CompletionInput& input) const;
  double thin_part_cell_size(const Mesh& mesh, const std::vector<Part>& parts, const CompletionInput& input, double h,
                             int& thin_part) const;
  bool simplify_part(CompletedPart& out, const Mesh& patch, double h) const;
  void close_small_parts(const CompletionInput& input, const PartBoxes& boxes, Completion& result) const;

  double resolution_ = 160;                 // cells along the object's longest side
  double max_resolution_ = 256;             // the finest grid thin parts may ask for (cells along the longest side)
  double refine_min_area_fraction_ = 0.01;  // parts with less of the total area do not refine the grid
  double simplify_ = 0.1;  // largest surface change of the simplification, cells (0 = keep every triangle)
  // Larger surfaces are not simplified: on the shared assets such attempts
  // almost always end with touching sheets (and the dense surface) and cost
  // about twice the rest of the stage (docs/performance.md).
  int simplify_max_triangles_ = 100'000;
  bool nested_ = false;          // closing one small part on its own grid
  double min_cells_across_ = 4;  // a stick-like part's second-largest extent spans at least this many cells
  int gap_ = 2;                  // closing radius, cells
  double max_cells_ = 1 << 24;   // memory guard: grid points (about 30 bytes each)
  // A part whose surface strays farther from its patch (x the patch's
  // diagonal) fails. Off by default: partition surfaces lie inside the object
  // by construction, and a small patch on a large body (a button on a
  // cushion) rightly claims the volume beneath it.
  double max_relative_distance_ = std::numeric_limits<double>::infinity();
};

Result<Completion> PartitionCompleter::complete(const CompletionInput& input) const {
  if (input.mesh == nullptr || input.parts == nullptr)
    return Status::InvalidArgument("partition: needs the mesh and the parts");
  const Mesh& mesh = *input.mesh;
  const std::vector<Part>& parts = *input.parts;
  G2P_RETURN_IF_ERROR(validate(mesh));
  Result<std::vector<int>> face_part = face_parts(mesh, parts);
  if (!face_part.ok()) return face_part.status();
  Result<GridChoice> choice = size_grid(mesh, parts, input);
  if (!choice.ok()) return choice.status();
  const Grid& g = choice->grid;
  const double h = choice->h;
  Completion result;
  result.notes.push_back(grid_note(*choice));
  result.grid_spacing_m = h;

  const auto t0 = std::chrono::steady_clock::now();
  auto lap = [last = t0]() mutable {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last).count();
    last = now;
    return static_cast<long>(ms);
  };
  std::ostringstream timing;
  // ---- 1. Distances ----------------------------------------------------------
  SurfaceBand band = exact_distances_near_surface(mesh, g, h);  // for the labels below
  timing << "distances " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.15, "distances"));
  std::vector<float> dist2 = band.dist2;  // cells^2, everywhere once transformed
  distance_transform(g, dist2, nullptr);
  timing << ", transform " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.3, "distance transform"));

  // ---- 2. Inside and outside ---------------------------------------------------
  std::vector<std::uint8_t> state = inside_outside_by_closing(g, dist2, choice->gap);
  timing << ", closing " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.45, "inside and outside"));
  Result<std::unique_ptr<detail::SegmentTester>> tester = detail::SegmentTester::create(mesh);
  if (!tester.ok()) return tester.status();
  const std::vector<std::size_t> near_surface = near_surface_points(band.nearest);
  correct_near_surface(g, h, **tester, near_surface, state);
  const int sheet_points = keep_open_sheets(g, h, **tester, near_surface, dist2, band.nearest, state);
  if (sheet_points > 0)
    result.notes.push_back(std::to_string(sheet_points) +
                           " grid points kept as slabs of open sheets (surfaces with outside on both sides)");
  timing << ", surface layer " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.6, "surface layer"));
  std::vector<int> seed_part = *face_part;  // kept parts do not claim the interior near them
  for (std::size_t f = 0; f < seed_part.size(); ++f)
    if (seed_part[f] >= 0 && input.is_kept(static_cast<std::size_t>(seed_part[f]))) seed_part[f] = -1;
  std::vector<int> label = interior_labels_from_skin(g, state, band, seed_part);
  give_kept_solids(g, input, label);
  timing << ", labels " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.7, "interior labels"));
  const std::vector<float> field = signed_field(dist2, state);
  dist2 = {};
  band = {};

  // ---- 3. Surfaces -------------------------------------------------------------
  const Mesh object = extract_surface(g, Eigen::Vector3i::Zero(), Eigen::Vector3i(g.nx - 1, g.ny - 1, g.nz - 1),
                                      [&](std::size_t i) { return field[i]; });
  result.object_volume_m3 = signed_volume(object);
  timing << ", object surface " << lap() << " ms";
  G2P_RETURN_IF_ERROR(input.report(0.8, "object surface"));
  const int np = static_cast<int>(parts.size());
  const PartBoxes boxes = part_boxes(g, field, label, np);
  result.parts.resize(static_cast<std::size_t>(np));
  tbb::parallel_for(0, np, [&](int p) {
    CompletedPart& out = result.parts[static_cast<std::size_t>(p)];
    out.part = p;
    out.label = parts[static_cast<std::size_t>(p)].label;
    out.backend = "partition";
    if (input.is_kept(static_cast<std::size_t>(p))) return;     // complete() keeps it as given
    if (boxes.hi[static_cast<std::size_t>(p)].x() < 0) return;  // smaller than a cell: closed on its own below
    out.mesh = part_surface(g, field, label, boxes, p);
    const Mesh patch = part_patch(mesh, parts[static_cast<std::size_t>(p)]);
    if (!simplify_part(out, patch, h)) out.checks = check_closed_mesh(out.mesh, &patch);
    out.ok = out.checks.watertight() && out.checks.relative_distance <= max_relative_distance_;
    if (!out.ok) out.notes.push_back("partition: the closed surface failed its checks");
  });
  timing << ", parts and checks " << lap() << " ms";
  if (!nested_) close_small_parts(input, boxes, result);
  result.notes.push_back(timing.str());
  for (const CompletedPart& p : result.parts) result.parts_volume_m3 += p.checks.volume_m3;
  return result;
}

// The grid: the cell size from the object's longest side, finer for a
// thin, stick-like part (fragments such as screws and labels do not set the
// resolution), padded by `gap` + 2 cells and coarsened until it has at most
// max_cells points.
Result<GridChoice> PartitionCompleter::size_grid(const Mesh& mesh, const std::vector<Part>& parts,
                                                 const CompletionInput& input) const {
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p.cast<double>());
  const Eigen::Vector3d ext = box.sizes();
  const double longest = ext.maxCoeff();
  if (!(longest > 0)) return Status::InvalidArgument("partition: the mesh has no extent");
  GridChoice choice;
  double h = std::max(thin_part_cell_size(mesh, parts, input, longest / resolution_, choice.thin_part),
                      longest / max_resolution_);
  // Openings as wide as the thin wall the caller measured are closed: the
  // outside floods through points farther than `gap` cells from the surface,
  // and a wall's middle lies half its thickness from it.
  choice.gap = gap_;
  if (input.thin_thickness_m > 0) {
    const int wide = static_cast<int>(std::ceil(0.6 * input.thin_thickness_m / h));
    if (wide > gap_) choice.gap = std::min(wide, 16), choice.widened = true;
  }
  const int pad = choice.gap + 2;
  Grid& g = choice.grid;
  for (int attempt = 0; attempt < 64; ++attempt) {
    g.h = h;
    g.nx = static_cast<int>(std::floor(ext.x() / h)) + 2 + 2 * pad;
    g.ny = static_cast<int>(std::floor(ext.y() / h)) + 2 + 2 * pad;
    g.nz = static_cast<int>(std::floor(ext.z() / h)) + 2 + 2 * pad;
    const double cells = static_cast<double>(g.nx) * g.ny * g.nz;
    if (cells <= max_cells_) break;
    h *= std::cbrt(cells / max_cells_) * 1.01;
  }
  g.origin = box.min() - pad * h * Eigen::Vector3d::Ones();
  choice.h = h;
  return choice;
}

// The cell size `h`, made finer where a part with at least
// refine_min_area_fraction of the area (and not kept as given) has a
// second-largest extent of fewer than min_cells_across cells; `thin_part` is
// the last part that refined it.
double PartitionCompleter::thin_part_cell_size(const Mesh& mesh, const std::vector<Part>& parts,
                                               const CompletionInput& input, double h, int& thin_part) const {
  double total_area = 0.0;
  for (const Part& p : parts) total_area += p.area_m2;
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) {
    // Fragments (screws, labels) do not set the resolution of the whole object.
    if (parts[static_cast<std::size_t>(p)].area_m2 < refine_min_area_fraction_ * total_area) continue;
    if (input.is_kept(static_cast<std::size_t>(p))) continue;  // kept as given: needs no grid
    Eigen::AlignedBox3d pb;
    for (int f : parts[static_cast<std::size_t>(p)].faces)
      for (int c = 0; c < 3; ++c)
        pb.extend(
            mesh.positions[static_cast<std::size_t>(mesh.triangles[static_cast<std::size_t>(f)][c])].cast<double>());
    if (pb.isEmpty()) continue;
    Eigen::Vector3d e = pb.sizes();
    std::sort(e.data(), e.data() + 3);
    if (min_cells_across_ > 0 && e[1] > 0 && e[1] / min_cells_across_ < h) {
      h = e[1] / min_cells_across_;
      thin_part = p;
    }
  }
  return h;
}

// Simplification: marching tetrahedra makes about six triangles per
// surface cell; collapse those that change the surface by less than
// `simplify` cells. Where that makes the surface touch itself (collapses along
// flat, grid-aligned faces can put a vertex on another sheet's edge), keep the
// dense surface. Returns true if `out` now holds the simplified surface and
// its checks; otherwise its dense surface is kept, unchecked, and a note may
// say why.
bool PartitionCompleter::simplify_part(CompletedPart& out, const Mesh& patch, double h) const {
  const double tolerance = simplify_;
  if (!(tolerance > 0)) return false;
  if (out.mesh.num_faces() > simplify_max_triangles_) {
    out.notes.push_back("partition: " + std::to_string(out.mesh.num_faces()) +
                        " triangles, more than simplify_max_triangles; not simplified");
    return false;
  }
  Mesh simplified = out.mesh;
  detail::simplify_closed_mesh(simplified, tolerance * h);
  MeshChecks checks = check_closed_mesh(simplified, &patch);
  if (checks.watertight()) {
    out.mesh = std::move(simplified);
    out.checks = checks;
    return true;
  }
  out.notes.push_back(
      "partition: simplifying by " + std::to_string(tolerance) + " cells " +
      (checks.outward ? "made " + std::to_string(checks.num_self_intersections) + " triangle pairs touch or intersect"
                      : std::string("folded the surface onto itself (no volume left)")) +
      "; the dense surface is kept");
  return false;
}

// Parts smaller than a cell own no grid point: each is closed on its own, on
// a grid sized from the part. Such a part may overlap its neighbours by up to
// a cell of the object's grid.
void PartitionCompleter::close_small_parts(const CompletionInput& input, const PartBoxes& boxes,
                                           Completion& result) const {
  const std::vector<Part>& parts = *input.parts;
  PartitionCompleter single = *this;
  single.nested_ = true;
  single.resolution_ = single.max_resolution_ = 32;  // small parts need volume, not detail
  for (int p = 0; p < static_cast<int>(parts.size()); ++p) {
    CompletedPart& out = result.parts[static_cast<std::size_t>(p)];
    if (boxes.hi[static_cast<std::size_t>(p)].x() >= 0 || input.is_kept(static_cast<std::size_t>(p))) continue;
    const Mesh patch = part_patch(*input.mesh, parts[static_cast<std::size_t>(p)]);
    const std::vector<Part> alone = {whole_patch_part(patch, parts[static_cast<std::size_t>(p)])};
    Result<Completion> own = single.complete(CompletionInput{&patch, &alone, input.table, nullptr, 0.0, {}});
    if (!own.ok() || own->parts.empty() || own->parts[0].mesh.num_faces() == 0) {
      out.notes.push_back("partition: the part is smaller than a cell and could not be closed on its own" +
                          (own.ok() ? std::string() : ": " + own.status().message()));
      continue;
    }
    std::vector<std::string> notes = {"partition: smaller than a cell of the object's grid; closed on its own (" +
                                      own->notes.front() + "), may overlap its neighbours"};
    out = std::move(own->parts[0]);
    out.part = p;
    for (auto& note : out.notes) notes.push_back(std::move(note));
    out.notes = std::move(notes);
  }
}

}  // namespace

std::unique_ptr<Completer> make_partition_completer() { return std::make_unique<PartitionCompleter>(); }

}  // namespace g2p
