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
#include "complete/segment_tester.h"
#include "complete/simplify.h"
#include "core/settings.h"

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
};

// Squared distances along one line: d[q] = min_p (q - p)^2 + f[p] over the
// finite samples, with the part of the minimising sample.
void transform_line(const float* f, const int* label, int n, float* d, int* label_out, int* v, double* z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!(f[q] < kInf)) continue;
    const double fq = f[q] + static_cast<double>(q) * q;
    double s = -std::numeric_limits<double>::infinity();
    while (k >= 0) {
      const int p = v[k];
      s = (fq - (f[p] + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (s <= z[k]) {
        --k;
        s = -std::numeric_limits<double>::infinity();
      } else {
        break;
      }
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0) {
    std::fill(d, d + n, kInf);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const int p = v[j];
    d[q] = static_cast<float>(static_cast<double>(q - p) * (q - p) + f[p]);
    if (label_out != nullptr) label_out[q] = label[p];
  }
}

// In place: f (squared distance in cells^2, infinity where no sample) becomes
// the squared distance to the nearest sample plus its value; `label`, if
// given, the nearest sample's label.
void distance_transform(const Grid& g, std::vector<float>& f, std::vector<int>* label) {
  const int dims[3] = {g.nx, g.ny, g.nz};
  const std::size_t strides[3] = {1, static_cast<std::size_t>(g.nx), static_cast<std::size_t>(g.nx) * g.ny};
  for (int axis = 0; axis < 3; ++axis) {
    const int n = dims[axis];
    const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
    const int lines = dims[a1] * dims[a2];
    tbb::parallel_for(tbb::blocked_range<int>(0, lines, 64), [&](const tbb::blocked_range<int>& r) {
      std::vector<float> in(static_cast<std::size_t>(n)), out(static_cast<std::size_t>(n));
      std::vector<int> lin(static_cast<std::size_t>(n)), lout(static_cast<std::size_t>(n)),
          v(static_cast<std::size_t>(n));
      std::vector<double> z(static_cast<std::size_t>(n) + 1);
      for (int line = r.begin(); line != r.end(); ++line) {
        const std::size_t base = static_cast<std::size_t>(line % dims[a1]) * strides[a1] +
                                 static_cast<std::size_t>(line / dims[a1]) * strides[a2];
        const std::size_t s = strides[axis];
        for (int q = 0; q < n; ++q) in[static_cast<std::size_t>(q)] = f[base + q * s];
        if (label != nullptr)
          for (int q = 0; q < n; ++q) lin[static_cast<std::size_t>(q)] = (*label)[base + q * s];
        transform_line(in.data(), lin.data(), n, out.data(), label != nullptr ? lout.data() : nullptr, v.data(),
                       z.data());
        for (int q = 0; q < n; ++q) f[base + q * s] = out[static_cast<std::size_t>(q)];
        if (label != nullptr)
          for (int q = 0; q < n; ++q) (*label)[base + q * s] = lout[static_cast<std::size_t>(q)];
      }
    });
  }
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

class PartitionCompleter final : public Completer {
 public:
  Status configure(const BackendSettings& settings) override {
    for (const auto& [key, value] : settings) {
      double v = 0;
      if (!detail::parse_double(value, v))
        return Status::InvalidArgument("partition: " + key + " needs a number, got '" + value + "'");
      if (key == "resolution" && v >= 8 && v <= 2048)
        resolution_ = v;
      else if (key == "max_resolution" && v >= 8 && v <= 2048)
        max_resolution_ = v;
      else if (key == "min_cells_across" && v >= 0 && v <= 64)
        min_cells_across_ = v;
      else if (key == "simplify" && v >= 0 && v <= 1)
        simplify_ = v;
      else if (key == "simplify_max_triangles" && v >= 0 && v <= 1e9 && v == std::floor(v))
        simplify_max_triangles_ = static_cast<int>(v);
      else if (key == "refine_min_area_fraction" && v >= 0 && v <= 1)
        refine_min_area_fraction_ = v;
      else if (key == "gap" && v >= 1 && v <= 16 && v == std::floor(v))
        gap_ = static_cast<int>(v);
      else if (key == "max_cells" && v >= 1e3 && v <= 1e9)
        max_cells_ = v;
      else if (key == "max_relative_distance" && v > 0)  // checked on every part
        max_relative_distance_ = v;
      else
        return Status::InvalidArgument(
            "partition: bad setting " + key + "=" + value +
            " (known: resolution and max_resolution in [8, 2048], min_cells_across in "
            "[0, 64], refine_min_area_fraction and simplify in [0, 1], simplify_max_triangles >= 0, gap an integer in "
            "[1, 16], max_cells in [1e3, 1e9], "
            "max_relative_distance > 0)");
    }
    return Status::Ok();
  }

  Result<Completion> complete(const CompletionInput& input) const override;

 private:
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

  // ---- Grid -----------------------------------------------------------------
  Eigen::AlignedBox3d box;
  for (const auto& p : mesh.positions) box.extend(p.cast<double>());
  const Eigen::Vector3d ext = box.sizes();
  const double longest = ext.maxCoeff();
  if (!(longest > 0)) return Status::InvalidArgument("partition: the mesh has no extent");
  Completion result;
  double h = longest / resolution_;
  int thin_part = -1;
  double total_area = 0.0;
  for (const Part& p : parts) total_area += p.area_m2;
  for (int p = 0; p < np; ++p) {
    // Fragments (screws, labels) do not set the resolution of the whole object.
    if (parts[static_cast<std::size_t>(p)].area_m2 < refine_min_area_fraction_ * total_area) continue;
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
  h = std::max(h, longest / max_resolution_);
  const int pad = gap_ + 2;
  Grid g;
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
  const std::size_t n = g.size();
  {
    std::ostringstream note;
    note.precision(3);
    note << "grid " << g.nx << "x" << g.ny << "x" << g.nz << " points, cell " << h * 1000 << " mm";
    if (thin_part >= 0) note << " (refined for thin part " << thin_part << ")";
    result.notes.push_back(note.str());
  }
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
  std::vector<float> dist2(n, kInf);  // cells^2
  std::vector<int> nearest(n, -1);    // triangle, within one cell of the surface
  {
    std::vector<std::uint64_t> best(n, ~std::uint64_t{0});
    tbb::parallel_for(tbb::blocked_range<int>(0, nf, 2048), [&](const tbb::blocked_range<int>& r) {
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
              atomic_min(&best[g.at(i, j, k)],
                         (static_cast<std::uint64_t>(bits) << 32) | static_cast<std::uint32_t>(t));
            }
      }
    });
    for (std::size_t i = 0; i < n; ++i) {
      if (best[i] == ~std::uint64_t{0}) continue;
      const auto bits = static_cast<std::uint32_t>(best[i] >> 32);
      std::memcpy(&dist2[i], &bits, sizeof bits);
      nearest[i] = static_cast<int>(best[i] & 0xffffffffu);
    }
  }
  timing << "distances " << lap() << " ms";
  const std::vector<float> band = dist2;  // exact squared distances within one cell, for the labels below
  distance_transform(g, dist2, nullptr);

  // ---- 2. Inside and outside ---------------------------------------------------
  timing << ", transform " << lap() << " ms";
  const float core_d2 = static_cast<float>(gap_) * gap_;
  std::vector<float> to_core(n, kInf);
  {
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
  }
  distance_transform(g, to_core, nullptr);  // grow the flooded core back by `gap` cells
  std::vector<std::uint8_t> state(n, 0);    // 0 inside, 1 outside, 2 kept as a slab of an open sheet
  for (std::size_t i = 0; i < n; ++i) state[i] = to_core[i] <= core_d2 + 1e-3f ? 1 : 0;
  to_core = {};
  timing << ", closing " << lap() << " ms";
  // The closing leaves a thin layer of outside points next to the surface
  // marked inside where its ball, centred on grid points, cannot reach (up to
  // about half a cell on curved or slanted faces). A point within a cell of
  // the surface that sees an outside neighbour without crossing the surface
  // is outside too; two rounds, so the fix stays next to where the closing
  // decided and cannot leak through the gaps it sealed.
  Result<std::unique_ptr<detail::SegmentTester>> tester = detail::SegmentTester::create(mesh);
  if (!tester.ok()) return tester.status();
  const detail::SegmentTester& segments = **tester;
  const std::size_t strides[3] = {1, static_cast<std::size_t>(g.nx), static_cast<std::size_t>(g.nx) * g.ny};
  const int dims[3] = {g.nx, g.ny, g.nz};
  auto coords = [&](std::size_t a) {
    return Eigen::Vector3i(static_cast<int>(a % strides[1]),
                           static_cast<int>((a / strides[1]) % static_cast<std::size_t>(g.ny)),
                           static_cast<int>(a / strides[2]));
  };
  std::vector<std::size_t> near_surface;
  for (std::size_t i = 0; i < n; ++i)
    if (nearest[i] >= 0) near_surface.push_back(i);
  int relabelled = 0;
  for (int round = 0; round < 2; ++round) {
    std::vector<std::uint8_t> flip(near_surface.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, near_surface.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t x = r.begin(); x != r.end(); ++x) {
                          const std::size_t a = near_surface[x];
                          if (state[a] != 0) continue;
                          const Eigen::Vector3i c = coords(a);
                          const Eigen::Vector3d pa = g.point(c.x(), c.y(), c.z());
                          for (int axis = 0; axis < 3 && !flip[x]; ++axis)
                            for (int side : {-1, 1}) {
                              if (c[axis] + side < 0 || c[axis] + side >= dims[axis]) continue;
                              const std::size_t b = side > 0 ? a + strides[axis] : a - strides[axis];
                              if (state[b] != 1) continue;
                              if (!segments.crosses(pa, pa + side * h * Eigen::Vector3d::Unit(axis))) {
                                flip[x] = 1;
                                break;
                              }
                            }
                        }
                      });
    for (std::size_t x = 0; x < near_surface.size(); ++x)
      if (flip[x]) {
        state[near_surface[x]] = 1;
        ++relabelled;
      }
  }

  // Open sheets the closing cannot see (a grid edge crosses the surface but
  // both its ends are outside) keep their nearer end as a thin slab.
  int sheet_points = 0;
  for (std::size_t a : near_surface) {
    if (state[a] == 0) continue;
    const Eigen::Vector3i c = coords(a);
    for (int axis = 0; axis < 3; ++axis) {
      if (c[axis] + 1 >= dims[axis]) continue;
      const std::size_t b = a + strides[axis];
      if (state[b] == 0 || nearest[b] < 0) continue;
      const Eigen::Vector3d pa = g.point(c.x(), c.y(), c.z());
      if (!segments.crosses(pa, pa + h * Eigen::Vector3d::Unit(axis))) continue;
      const std::size_t keep = dist2[a] <= dist2[b] ? a : b;
      if (state[keep] != 2) ++sheet_points;
      state[keep] = 2;
    }
  }
  if (sheet_points > 0)
    result.notes.push_back(std::to_string(sheet_points) +
                           " grid points kept as slabs of open sheets (surfaces with outside on both sides)");

  timing << ", surface layer " << lap() << " ms";
  // The interior goes to the part of the nearest surface on the object's
  // skin: grid points within a cell of the surface where inside meets
  // outside. Surfaces with inside on both sides (the coincident faces of two
  // touching boxes, hidden inner walls) do not claim volume.
  std::vector<float> seed(n, kInf);
  std::vector<int> label(n, -1);  // part of the nearest skin surface
  {
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) {
          const std::size_t a = g.at(i, j, k);
          if (nearest[a] < 0) continue;
          const int coord[3] = {i, j, k};
          const bool out_a = state[a] == 1;
          bool skin = false;
          for (int axis = 0; axis < 3 && !skin; ++axis) {
            if (coord[axis] > 0) skin |= (state[a - strides[axis]] == 1) != out_a;
            if (coord[axis] + 1 < dims[axis]) skin |= (state[a + strides[axis]] == 1) != out_a;
          }
          if (!skin) continue;
          seed[a] = band[a];
          label[a] = face_part[static_cast<std::size_t>(nearest[a])];
        }
  }
  distance_transform(g, seed, &label);
  seed = {};

  timing << ", labels " << lap() << " ms";
  // Signed field in cells; never exactly zero so no vertex sits on a grid point.
  constexpr float kMinMagnitude = 0.02f;
  std::vector<float> field(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float d = std::max(std::sqrt(dist2[i]), kMinMagnitude);
    field[i] = state[i] == 1 ? d : state[i] == 2 ? -0.25f : -d;
  }
  dist2 = {};
  nearest = {};

  // ---- 3. Surfaces -------------------------------------------------------------
  const Eigen::Vector3i all_lo = Eigen::Vector3i::Zero(), all_hi(g.nx - 1, g.ny - 1, g.nz - 1);
  const Mesh object = extract_surface(g, all_lo, all_hi, [&](std::size_t i) { return field[i]; });
  result.object_volume_m3 = signed_volume(object);
  timing << ", object surface " << lap() << " ms";

  std::vector<Eigen::Vector3i> lo(static_cast<std::size_t>(np),
                                  Eigen::Vector3i::Constant(std::numeric_limits<int>::max()));
  std::vector<Eigen::Vector3i> hi(static_cast<std::size_t>(np), Eigen::Vector3i::Constant(-1));
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t x = g.at(i, j, k);
        const int p = label[x];
        if (field[x] >= 0 || p < 0) continue;
        lo[static_cast<std::size_t>(p)] = lo[static_cast<std::size_t>(p)].cwiseMin(Eigen::Vector3i(i, j, k));
        hi[static_cast<std::size_t>(p)] = hi[static_cast<std::size_t>(p)].cwiseMax(Eigen::Vector3i(i, j, k));
      }

  result.parts.resize(static_cast<std::size_t>(np));
  tbb::parallel_for(0, np, [&](int p) {
    CompletedPart& out = result.parts[static_cast<std::size_t>(p)];
    out.part = p;
    out.label = parts[static_cast<std::size_t>(p)].label;
    out.backend = "partition";
    if (hi[static_cast<std::size_t>(p)].x() < 0) return;  // smaller than a cell: closed on its own below
    const Eigen::Vector3i plo = (lo[static_cast<std::size_t>(p)] - Eigen::Vector3i::Ones()).cwiseMax(0);
    const Eigen::Vector3i phi = (hi[static_cast<std::size_t>(p)] + Eigen::Vector3i::Ones()).cwiseMin(all_hi);
    out.mesh = extract_surface(g, plo, phi, [&](std::size_t i) {
      const float f = field[i];
      if (f >= 0) return f;
      return std::max(f, label[i] == p ? -0.5f : 0.5f);
    });
    const Mesh patch = part_patch(mesh, parts[static_cast<std::size_t>(p)]);
    // Marching tetrahedra makes about six triangles per surface cell; collapse
    // those that change the surface by less than `simplify` cells. Where that
    // makes the surface touch itself (collapses along flat, grid-aligned faces
    // can put a vertex on another sheet's edge), keep the dense surface.
    bool done = false;
    for (double tolerance : {simplify_}) {
      if (!(tolerance > 0)) break;
      if (out.mesh.num_faces() > simplify_max_triangles_) {
        out.notes.push_back("partition: " + std::to_string(out.mesh.num_faces()) +
                            " triangles, more than simplify_max_triangles; not simplified");
        break;
      }
      Mesh simplified = out.mesh;
      detail::simplify_closed_mesh(simplified, tolerance * h);
      MeshChecks checks = check_closed_mesh(simplified, &patch);
      if (checks.watertight()) {
        out.mesh = std::move(simplified);
        out.checks = checks;
        done = true;
        break;
      }
      out.notes.push_back("partition: simplifying by " + std::to_string(tolerance) + " cells " +
                          (checks.outward ? "made " + std::to_string(checks.num_self_intersections) +
                                                " triangle pairs touch or intersect"
                                          : std::string("folded the surface onto itself (no volume left)")) +
                          "; the dense surface is kept");
    }
    if (!done) out.checks = check_closed_mesh(out.mesh, &patch);
    out.ok = out.checks.watertight() && out.checks.relative_distance <= max_relative_distance_;
    if (!out.ok) out.notes.push_back("partition: the closed surface failed its checks");
  });
  timing << ", parts and checks " << lap() << " ms";
  // Parts smaller than a cell own no grid point: each is closed on its own,
  // on a grid sized from the part. Such a part may overlap its neighbours by
  // up to a cell of the object's grid.
  if (!nested_) {
    PartitionCompleter single = *this;
    single.nested_ = true;
    single.resolution_ = single.max_resolution_ = 32;  // small parts need volume, not detail
    for (int p = 0; p < np; ++p) {
      CompletedPart& out = result.parts[static_cast<std::size_t>(p)];
      if (hi[static_cast<std::size_t>(p)].x() >= 0) continue;
      const Mesh patch = part_patch(mesh, parts[static_cast<std::size_t>(p)]);
      const std::vector<Part> alone = {Part{out.label,
                                            [&] {
                                              std::vector<int> f(static_cast<std::size_t>(patch.num_faces()));
                                              for (int i = 0; i < patch.num_faces(); ++i)
                                                f[static_cast<std::size_t>(i)] = i;
                                              return f;
                                            }(),
                                            parts[static_cast<std::size_t>(p)].area_m2}};
      Result<Completion> own = single.complete(CompletionInput{&patch, &alone, input.table});
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
  result.notes.push_back(timing.str());
  for (const CompletedPart& p : result.parts) result.parts_volume_m3 += p.checks.volume_m3;
  return result;
}

}  // namespace

std::unique_ptr<Completer> make_partition_completer() { return std::make_unique<PartitionCompleter>(); }

}  // namespace g2p
