#include "complete/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace g2p::detail {

using Eigen::Vector3d;

Vector3d closest_point_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;  // vertex region A
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;  // vertex region B
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));  // edge AB
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;  // vertex region C
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));  // edge AC
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));  // BC
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return a;  // degenerate triangle
  const double v = vb / denom, w = vc / denom;
  return a + ab * v + ac * w;  // face interior
}

bool segment_hits_triangle(const Vector3d& p, const Vector3d& q, const Vector3d& a, const Vector3d& b,
                           const Vector3d& c) {
  const Vector3d dir = q - p, e1 = b - a, e2 = c - a;
  const Vector3d pv = dir.cross(e2);
  const double det = e1.dot(pv);
  const double scale = e1.norm() * e2.norm() * dir.norm();
  if (!(std::abs(det) > 1e-12 * scale)) return false;  // parallel or degenerate
  const double inv = 1.0 / det;
  const Vector3d tv = p - a;
  const double u = tv.dot(pv) * inv;
  if (u < 0 || u > 1) return false;
  const Vector3d qv = tv.cross(e1);
  const double v = dir.dot(qv) * inv;
  if (v < 0 || u + v > 1) return false;
  const double t = e2.dot(qv) * inv;
  constexpr double kEps = 1e-9;
  return t > kEps && t < 1 - kEps;
}

bool triangles_intersect(const Vector3d t0[3], const Vector3d t1[3]) {
  for (int e = 0; e < 3; ++e) {
    if (segment_hits_triangle(t0[e], t0[(e + 1) % 3], t1[0], t1[1], t1[2])) return true;
    if (segment_hits_triangle(t1[e], t1[(e + 1) % 3], t0[0], t0[1], t0[2])) return true;
  }
  return false;
}

TriangleBins::TriangleBins(const Mesh& mesh, double triangles_per_cell) : mesh_(mesh) {
  const int nf = mesh.num_faces();
  for (const auto& p : mesh.positions) box_.extend(p.cast<double>());
  if (nf == 0 || box_.isEmpty()) {
    start_.assign(2, 0);
    return;
  }
  // Cell size from the mean triangle size and the box, so both tiny and huge
  // triangles give a bounded number of cells.
  const Vector3d ext = box_.sizes().cwiseMax(1e-9);
  const double cells = std::max(1.0, nf / std::max(triangles_per_cell, 0.5));
  cell_ = std::cbrt(ext.prod() / cells);
  // Flat or thin boxes: do not let one axis explode the cell count.
  cell_ = std::max(cell_, ext.maxCoeff() / 256.0);
  dims_ = (ext / cell_).array().ceil().cast<int>().max(1).matrix();
  const long long ncell = static_cast<long long>(dims_.x()) * dims_.y() * dims_.z();
  std::vector<int> count(static_cast<std::size_t>(ncell) + 1, 0);
  auto for_cells = [&](int t, auto&& fn) {
    Eigen::AlignedBox3d tb;
    for (int c = 0; c < 3; ++c) tb.extend(tri(t, c));
    const Eigen::Vector3i lo = cell_of(tb.min()), hi = cell_of(tb.max());
    for (int k = lo.z(); k <= hi.z(); ++k)
      for (int j = lo.y(); j <= hi.y(); ++j)
        for (int i = lo.x(); i <= hi.x(); ++i) fn(index(i, j, k));
  };
  for (int t = 0; t < nf; ++t) for_cells(t, [&](long long c) { ++count[static_cast<std::size_t>(c) + 1]; });
  for (std::size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
  start_ = count;
  items_.resize(static_cast<std::size_t>(count.back()));
  for (int t = 0; t < nf; ++t) for_cells(t, [&](long long c) { items_[static_cast<std::size_t>(count[c]++)] = t; });
}

Vector3d TriangleBins::tri(int t, int corner) const {
  return mesh_.positions[static_cast<std::size_t>(mesh_.triangles[static_cast<std::size_t>(t)][corner])].cast<double>();
}

Eigen::Vector3i TriangleBins::cell_of(const Vector3d& p) const {
  const Vector3d r = (p - box_.min()) / cell_;
  Eigen::Vector3i c;
  // Clamped before the cast: a point far outside the box (a query against a
  // tiny patch) lies beyond int's range in cells.
  for (int a = 0; a < 3; ++a)
    c[a] = static_cast<int>(std::clamp(std::floor(r[a]), 0.0, static_cast<double>(dims_[a] - 1)));
  return c;
}

double TriangleBins::distance(const Vector3d& p, double enough) const {
  if (items_.empty()) return std::numeric_limits<double>::infinity();
  // Search shells of cells around p's (clamped) cell until the best distance
  // found is below the distance to the next shell.
  const Eigen::Vector3i c0 = cell_of(p);
  double best = std::numeric_limits<double>::infinity();
  const int max_ring = dims_.maxCoeff();
  for (int ring = 0; ring <= max_ring; ++ring) {
    for (int k = c0.z() - ring; k <= c0.z() + ring; ++k) {
      if (k < 0 || k >= dims_.z()) continue;
      for (int j = c0.y() - ring; j <= c0.y() + ring; ++j) {
        if (j < 0 || j >= dims_.y()) continue;
        for (int i = c0.x() - ring; i <= c0.x() + ring; ++i) {
          if (i < 0 || i >= dims_.x()) continue;
          if (std::max({std::abs(i - c0.x()), std::abs(j - c0.y()), std::abs(k - c0.z())}) != ring) continue;
          const long long c = index(i, j, k);
          for (int s = start_[static_cast<std::size_t>(c)]; s < start_[static_cast<std::size_t>(c) + 1]; ++s) {
            const int t = items_[static_cast<std::size_t>(s)];
            const Vector3d q = closest_point_on_triangle(p, tri(t, 0), tri(t, 1), tri(t, 2));
            best = std::min(best, (q - p).norm());
          }
          if (best <= enough) return best;
        }
      }
    }
    // Triangles not seen yet lie in cells beyond this ring, at least
    // `ring * cell_` from p (per axis, clamping p into the box only shortens distances).
    if (best <= ring * cell_) break;
  }
  return best;
}

std::vector<std::pair<int, int>> TriangleBins::intersecting_pairs(int max_pairs) const {
  std::vector<std::pair<int, int>> out;
  const long long ncell = static_cast<long long>(dims_.x()) * dims_.y() * dims_.z();
  const std::size_t nf = static_cast<std::size_t>(mesh_.num_faces());
  std::vector<Eigen::AlignedBox3d> boxes(nf);
  // Each triangle's plane (unit normal, offset) and a tolerance from its size:
  // a pair where one triangle lies wholly on one side of the other's plane
  // cannot intersect, which rules out most pairs before the edge tests.
  struct Plane {
    Vector3d normal = Vector3d::Zero();
    double offset = 0, tolerance = 0;
  };
  std::vector<Plane> planes(nf);
  std::vector<Eigen::Vector3i> low_cell(nf);  // the cell of each box's low corner
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const Vector3d a = tri(static_cast<int>(t), 0), b = tri(static_cast<int>(t), 1), c = tri(static_cast<int>(t), 2);
      boxes[t].extend(a).extend(b).extend(c);
      low_cell[t] = cell_of(boxes[t].min());
      const Vector3d n = (b - a).cross(c - a);
      const double length = n.norm();
      if (length > 0) planes[t] = {n / length, n.dot(a) / length, 1e-9 * boxes[t].diagonal().norm()};
    }
  });
  // Whether all three `corners` lie strictly on one side of plane `p`
  // (never for a degenerate `p`, whose normal is zero).
  auto one_side = [&](const Plane& p, const Vector3d corners[3]) {
    if (p.tolerance <= 0) return false;
    int above = 0, below = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = p.normal.dot(corners[k]) - p.offset;
      above += d > p.tolerance;
      below += d < -p.tolerance;
    }
    return above == 3 || below == 3;
  };
  // The pairs found in cell c, in the order of its items.
  auto pairs_in_cell = [&](long long c, std::vector<std::pair<int, int>>& found) {
    const int s0 = start_[static_cast<std::size_t>(c)], s1 = start_[static_cast<std::size_t>(c) + 1];
    for (int a = s0; a < s1; ++a) {
      const int ta = items_[static_cast<std::size_t>(a)];
      const Eigen::Vector3i& va = mesh_.triangles[static_cast<std::size_t>(ta)];
      for (int b = a + 1; b < s1; ++b) {
        const int tb = items_[static_cast<std::size_t>(b)];
        const Eigen::Vector3i& vb = mesh_.triangles[static_cast<std::size_t>(tb)];
        bool shared = false;
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 3; ++y) shared |= va[x] == vb[y];
        if (shared) continue;
        const auto& ba = boxes[static_cast<std::size_t>(ta)];
        const auto& bb = boxes[static_cast<std::size_t>(tb)];
        if (!ba.intersects(bb)) continue;
        // Test each pair once: in the cell holding the low corner of the
        // boxes' overlap, the larger low corner on each axis (cell_of is
        // monotone along each axis).
        const Eigen::Vector3i low =
            low_cell[static_cast<std::size_t>(ta)].cwiseMax(low_cell[static_cast<std::size_t>(tb)]);
        if (index(low.x(), low.y(), low.z()) != c) continue;
        const Vector3d t0[3] = {tri(ta, 0), tri(ta, 1), tri(ta, 2)};
        const Vector3d t1[3] = {tri(tb, 0), tri(tb, 1), tri(tb, 2)};
        if (one_side(planes[static_cast<std::size_t>(ta)], t1) || one_side(planes[static_cast<std::size_t>(tb)], t0))
          continue;
        if (triangles_intersect(t0, t1)) found.emplace_back(std::min(ta, tb), std::max(ta, tb));
      }
    }
  };
  // Cells in waves searched side by side, joined in cell order: the pairs of
  // whole cells until `max_pairs` is reached, as a loop over the cells in
  // order gives, without searching far beyond the cell that reaches it.
  constexpr long long kWave = 4096;
  std::vector<std::vector<std::pair<int, int>>> wave(static_cast<std::size_t>(std::min(kWave, ncell)));
  for (long long first = 0; first < ncell && static_cast<int>(out.size()) < max_pairs; first += kWave) {
    const long long last = std::min(ncell, first + kWave);
    tbb::parallel_for(tbb::blocked_range<long long>(first, last, 64), [&](const tbb::blocked_range<long long>& r) {
      for (long long c = r.begin(); c != r.end(); ++c) pairs_in_cell(c, wave[static_cast<std::size_t>(c - first)]);
    });
    for (long long c = first; c < last; ++c) {
      std::vector<std::pair<int, int>>& found = wave[static_cast<std::size_t>(c - first)];
      if (static_cast<int>(out.size()) < max_pairs) out.insert(out.end(), found.begin(), found.end());
      found.clear();
    }
  }
  return out;
}

}  // namespace g2p::detail
