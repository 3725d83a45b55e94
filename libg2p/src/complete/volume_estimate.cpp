// estimate_volumes: the volume inside the input's faces, measured along rays
// instead of on a grid, as the check every completed part is held to (#50).
//
// For each axis, a grid of rays_per_side^2 parallel rays covers the bounding
// box's face across it (rays at cell centres, nudged off the exact centre so
// that they do not run along the diagonals of axis-aligned quads). Triangles
// are binned by the rays their 2D bounds cover; each ray collects its
// crossings (position along the axis, entering or leaving by the triangle's
// normal, the triangle's part), sorts them (at one position, leaving before
// entering, so that two solids touching at a face stay two intervals) and
// pairs them:
//   - by winding number: inside wherever the running sum of +1 (entering) and
//     -1 (leaving) is not zero, the ray paired when the sum never changes sign
//     and ends at zero (nested shells, cavities and either global
//     orientation are fine);
//   - by parity, for rays whose orientation is inconsistent: inside between
//     crossings 1-2, 3-4, ..., paired when the count is even.
// A ray pairs by neither (an open sheet, a hole) is left out; each axis's
// volume is scaled by its hit rays over its paired ones, and the axes are
// averaged weighted by their paired rays (an axis along which no ray crosses
// the surface, such as one lying in a sheet's plane, says nothing).
// Every inside interval falls to the parts of its two ends, halfway each:
// the one-dimensional counterpart of the partition completer's nearest-
// surface rule, and exact when both ends are the same part.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "g2p/complete.h"

namespace g2p {
namespace {

struct Crossing {
  double t;  // along the axis, metres
  int sign;  // +1 entering (normal against the ray), -1 leaving
  int part;  // -1 for faces of no part
};

struct AxisTotals {
  double object = 0.0;
  std::vector<double> part, own;
  std::vector<int> intervals;
  int hit = 0, paired = 0;
  explicit AxisTotals(std::size_t np) : part(np, 0.0), own(np, 0.0), intervals(np, 0) {}
  void add(const AxisTotals& o) {
    object += o.object;
    for (std::size_t p = 0; p < part.size(); ++p) {
      part[p] += o.part[p];
      own[p] += o.own[p];
      intervals[p] += o.intervals[p];
    }
    hit += o.hit;
    paired += o.paired;
  }
};

enum class Pairing { kNone, kWinding, kParity };

// How one ray's sorted crossings pair up (see the top of the file).
Pairing pairing_of(const std::vector<Crossing>& c) {
  int w = 0, direction = 0;
  for (const Crossing& x : c) {
    w += x.sign;
    if (w == 0) continue;
    const int s = w > 0 ? 1 : -1;
    if (direction == 0) direction = s;
    if (s != direction) {
      w = 1;  // mixed signs: not by winding
      break;
    }
  }
  if (w == 0) return Pairing::kWinding;
  return c.size() % 2 == 0 ? Pairing::kParity : Pairing::kNone;
}

// Adds the inside intervals of one ray's sorted, paired crossings to
// `totals` (lengths, not yet times the ray's cross-section).
void add_intervals(const std::vector<Crossing>& c, Pairing how, AxisTotals& totals) {
  auto add_interval = [&](const Crossing& a, const Crossing& b) {
    const double length = b.t - a.t;
    if (!(length > 0)) return;
    totals.object += length;
    if (a.part >= 0) {
      totals.part[static_cast<std::size_t>(a.part)] += 0.5 * length;
      ++totals.intervals[static_cast<std::size_t>(a.part)];
    }
    if (b.part >= 0) {
      totals.part[static_cast<std::size_t>(b.part)] += 0.5 * length;
      if (b.part != a.part) ++totals.intervals[static_cast<std::size_t>(b.part)];
    }
    if (a.part >= 0 && a.part == b.part) totals.own[static_cast<std::size_t>(a.part)] += length;
  };
  if (how == Pairing::kWinding) {
    int running = 0;
    for (std::size_t i = 0; i + 1 < c.size(); ++i) {
      running += c[i].sign;
      if (running != 0) add_interval(c[i], c[i + 1]);
    }
  } else {
    for (std::size_t i = 0; i + 1 < c.size(); i += 2) add_interval(c[i], c[i + 1]);
  }
}

AxisTotals cast_axis(const Mesh& mesh, const std::vector<int>& face_part, std::size_t np, int axis, int n,
                     const Eigen::AlignedBox3d& box) {
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  const Eigen::Vector3d ext = box.sizes();
  AxisTotals totals(np);
  if (!(ext[b] > 0) || !(ext[c] > 0)) return totals;
  const double db = ext[b] / n, dc = ext[c] / n;
  // Ray (i, j) passes through (lo_b + (i + ob) db, lo_c + (j + oc) dc).
  constexpr double ob = 0.5 + 0.0718281828, oc = 0.5 - 0.0414213562;
  const double lo_b = box.min()[b], lo_c = box.min()[c];
  auto first_ray = [n](double lo, double offset) { return std::clamp(static_cast<int>(std::ceil(lo - offset)), 0, n); };
  auto last_ray = [n](double hi, double offset) {
    return std::clamp(static_cast<int>(std::floor(hi - offset)), -1, n - 1);
  };
  // Bin triangles by the rays their 2D bounds cover (compressed rows).
  const int nf = mesh.num_faces();
  std::vector<int> start(static_cast<std::size_t>(n) * n + 1, 0);
  auto for_each_ray = [&](int f, auto&& visit) {
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
    double min_b = 1e300, max_b = -1e300, min_c = 1e300, max_c = -1e300;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& p = mesh.positions[static_cast<std::size_t>(t[k])];
      min_b = std::min(min_b, static_cast<double>(p[b]));
      max_b = std::max(max_b, static_cast<double>(p[b]));
      min_c = std::min(min_c, static_cast<double>(p[c]));
      max_c = std::max(max_c, static_cast<double>(p[c]));
    }
    const int i0 = first_ray((min_b - lo_b) / db, ob), i1 = last_ray((max_b - lo_b) / db, ob);
    const int j0 = first_ray((min_c - lo_c) / dc, oc), j1 = last_ray((max_c - lo_c) / dc, oc);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) visit(static_cast<std::size_t>(j) * n + i);
  };
  for (int f = 0; f < nf; ++f) for_each_ray(f, [&](std::size_t r) { ++start[r + 1]; });
  for (std::size_t r = 0; r + 1 < start.size(); ++r) start[r + 1] += start[r];
  std::vector<int> items(static_cast<std::size_t>(start.back()));
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int f = 0; f < nf; ++f)
      for_each_ray(f, [&](std::size_t r) { items[static_cast<std::size_t>(fill[r]++)] = f; });
  }
  // Each row of rays on its own; rows summed afterwards, in order.
  std::vector<AxisTotals> rows(static_cast<std::size_t>(n), AxisTotals(np));
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& range) {
    std::vector<Crossing> crossings;
    for (int j = range.begin(); j != range.end(); ++j) {
      AxisTotals& row = rows[static_cast<std::size_t>(j)];
      const double pc = lo_c + (j + oc) * dc;
      for (int i = 0; i < n; ++i) {
        const std::size_t r = static_cast<std::size_t>(j) * n + i;
        const double pb = lo_b + (i + ob) * db;
        crossings.clear();
        for (int k = start[r]; k < start[r + 1]; ++k) {
          const int f = items[static_cast<std::size_t>(k)];
          const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
          std::array<Eigen::Vector3d, 3> v;
          for (int q = 0; q < 3; ++q) v[q] = mesh.positions[static_cast<std::size_t>(t[q])].cast<double>();
          // Edge functions in the (b, c) plane: the ray is inside when all
          // three have the sign of the triangle's projected area.
          auto edge = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
            return (q[b] - p[b]) * (pc - p[c]) - (q[c] - p[c]) * (pb - p[b]);
          };
          const double area = (v[1][b] - v[0][b]) * (v[2][c] - v[0][c]) - (v[1][c] - v[0][c]) * (v[2][b] - v[0][b]);
          if (area == 0.0) continue;  // edge-on to the ray
          const double w0 = edge(v[1], v[2]), w1 = edge(v[2], v[0]), w2 = edge(v[0], v[1]);
          const bool inside = area > 0 ? (w0 >= 0 && w1 >= 0 && w2 >= 0) : (w0 <= 0 && w1 <= 0 && w2 <= 0);
          if (!inside) continue;
          // From the first corner, so that a face across the axis gives its
          // coordinate exactly (touching solids' faces then tie).
          const double t_hit = v[0][axis] + (w1 * (v[1][axis] - v[0][axis]) + w2 * (v[2][axis] - v[0][axis])) / area;
          // The normal's component along the axis has the projected area's
          // sign: positive means the ray leaves through this face.
          crossings.push_back({t_hit, area > 0 ? -1 : 1, face_part[static_cast<std::size_t>(f)]});
        }
        if (crossings.empty()) continue;
        ++row.hit;
        std::sort(crossings.begin(), crossings.end(),
                  [](const Crossing& x, const Crossing& y) { return x.t < y.t || (x.t == y.t && x.sign < y.sign); });
        const Pairing how = pairing_of(crossings);
        if (how == Pairing::kNone) continue;
        ++row.paired;
        add_intervals(crossings, how, row);
      }
    }
  });
  for (const AxisTotals& row : rows) totals.add(row);
  const double cross_section = db * dc;
  const double scale = totals.paired > 0 ? cross_section * totals.hit / totals.paired : 0.0;
  totals.object *= scale;
  for (std::size_t p = 0; p < np; ++p) {
    totals.part[p] *= scale;
    totals.own[p] *= scale;
  }
  return totals;
}

}  // namespace

VolumeEstimate estimate_volumes(const Mesh& mesh, const std::vector<Part>& parts, int rays_per_side) {
  VolumeEstimate out;
  const std::size_t np = parts.size();
  out.part_m3.assign(np, 0.0);
  out.part_own_fraction.assign(np, 0.0);
  out.part_intervals.assign(np, 0);
  if (mesh.num_faces() == 0 || rays_per_side < 1) return out;
  std::vector<int> face_part(static_cast<std::size_t>(mesh.num_faces()), -1);
  for (std::size_t p = 0; p < np; ++p)
    for (int f : parts[p].faces)
      if (f >= 0 && f < mesh.num_faces()) face_part[static_cast<std::size_t>(f)] = static_cast<int>(p);
  const Eigen::AlignedBox3d box = bounds(mesh);
  std::vector<double> own(np, 0.0);
  double weight = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const AxisTotals a = cast_axis(mesh, face_part, np, axis, rays_per_side, box);
    out.rays_hit += a.hit;
    out.rays_paired += a.paired;
    const double w = a.paired;
    weight += w;
    out.object_m3 += w * a.object;
    for (std::size_t p = 0; p < np; ++p) {
      out.part_m3[p] += w * a.part[p];
      own[p] += w * a.own[p];
      out.part_intervals[p] += a.intervals[p];
    }
  }
  if (weight > 0) {
    out.object_m3 /= weight;
    for (std::size_t p = 0; p < np; ++p) {
      out.part_m3[p] /= weight;
      own[p] /= weight;
    }
  }
  for (std::size_t p = 0; p < np; ++p)
    out.part_own_fraction[p] = out.part_m3[p] > 0 ? std::min(1.0, own[p] / out.part_m3[p]) : 0.0;
  return out;
}

}  // namespace g2p
