// closed_part_surface: a part whose own faces already bound a solid needs no
// completion. Closing it anyway (on a grid, by wrapping) can only lose what
// the input says exactly: a 2 mm board on a grid of 4 mm cells keeps a tenth
// of its volume (#50). Such a part is kept face for face.
//
// The faces are welded (UV seams and split normals duplicate vertices), then
// must form a closed, consistently oriented, vertex-manifold surface without
// self-intersections. Its components may be nested (a cavity: an inward
// component inside an outward one); the winding number just inside and just
// outside every component must be 0 or 1, so that the divergence theorem
// gives the solid's volume and inertia. A component inside out that no other
// contains is turned; any other arrangement (overlapping solids, doubled
// shells, a nested component wound like the one around it, which could be a
// cavity or a second solid) is left to the completer.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>

#include <tbb/parallel_sort.h>

#include "complete/closed_parts.h"
#include "core/cell_index.h"
#include "core/union_find.h"
#include "g2p/complete.h"

namespace g2p {
namespace {

// The part's faces with every vertex numbered in the order first met (no
// array the size of the whole mesh: an object of a thousand parts is welded
// a thousand times).
struct LocalFaces {
  std::vector<int> vertex;               // mesh vertex of each local one
  std::vector<Eigen::Vector3i> corners;  // local corners of each face kept
  std::vector<int> face;                 // its index in the mesh
};

LocalFaces local_faces(const Mesh& mesh, const Part& part) {
  LocalFaces out;
  detail::CellIndex local(part.faces.size());  // mesh vertex -> local vertex
  out.corners.reserve(part.faces.size());
  out.face.reserve(part.faces.size());
  for (int f : part.faces) {
    if (f < 0 || f >= mesh.num_faces()) continue;
    Eigen::Vector3i t;
    for (int c = 0; c < 3; ++c) {
      const int v = mesh.triangles[static_cast<std::size_t>(f)][c];
      const int next = static_cast<int>(out.vertex.size());
      t[c] = local.at(static_cast<std::uint64_t>(v), next);
      if (t[c] == next) out.vertex.push_back(v);
    }
    out.corners.push_back(t);
    out.face.push_back(f);
  }
  return out;
}

// Local vertex representatives: each vertex's first earlier vertex within
// `eps` (a hash grid of cells 2 eps wide; of the 27 cells around a vertex's
// own, only those nearer than eps along every axis can hold one, at most 8).
std::vector<int> weld(const Mesh& mesh, const LocalFaces& part, double eps) {
  const std::size_t n = part.vertex.size();
  std::vector<int> rep(n);
  std::iota(rep.begin(), rep.end(), 0);
  if (!(eps > 0)) return rep;
  const double cell = 2.0 * eps;
  // A neighbour on the low (high) side along an axis is searched unless the
  // vertex lies in the high (low) half of its cell by more than rounding:
  // every point of that neighbour is then more than eps away.
  constexpr double kMargin = 1e-6;
  auto position = [&](int i) {
    return mesh.positions[static_cast<std::size_t>(part.vertex[static_cast<std::size_t>(i)])];
  };
  // Each cell's representatives, newest first: `head` in the index, then
  // `next`; the search wants the earliest within eps in a cell.
  detail::CellIndex cells(n);
  std::vector<int> next(n, -1);
  for (int v = 0; v < static_cast<int>(n); ++v) {
    const Eigen::Vector3d p = position(v).cast<double>() / cell;
    const Eigen::Vector3d lo = p.array().floor();
    const Eigen::Vector3d frac = p - lo;
    const long long x = static_cast<long long>(lo.x()), y = static_cast<long long>(lo.y()),
                    z = static_cast<long long>(lo.z());
    auto from = [&](int a) { return frac[a] > 0.5 + kMargin ? 0 : -1; };
    auto to = [&](int a) { return frac[a] < 0.5 - kMargin ? 0 : 1; };
    int found = -1;
    for (int dz = from(2); dz <= to(2) && found < 0; ++dz)
      for (int dy = from(1); dy <= to(1) && found < 0; ++dy)
        for (int dx = from(0); dx <= to(0) && found < 0; ++dx) {
          const int* head = cells.find(detail::CellIndex::key(x + dx, y + dy, z + dz));
          if (head == nullptr) continue;
          for (int r = *head; r >= 0; r = next[static_cast<std::size_t>(r)])
            if ((position(r) - position(v)).cast<double>().norm() <= eps) found = r;  // the last found is the earliest
        }
    if (found >= 0) {
      rep[static_cast<std::size_t>(v)] = found;
    } else {
      int& head = cells.at(detail::CellIndex::key(x, y, z), -1);
      next[static_cast<std::size_t>(v)] = head;
      head = v;
    }
  }
  return rep;
}

// The welded, compacted faces, without triangles that welding collapsed.
Mesh welded_part(const Mesh& mesh, const LocalFaces& part, const std::vector<int>& rep, std::vector<int>* source) {
  Mesh out;
  std::vector<int> index(part.vertex.size(), -1);  // representative -> compacted vertex
  auto vertex = [&](int v) {
    const int r = rep[static_cast<std::size_t>(v)];
    int& i = index[static_cast<std::size_t>(r)];
    if (i < 0) {
      i = static_cast<int>(out.positions.size());
      out.positions.push_back(mesh.positions[static_cast<std::size_t>(part.vertex[static_cast<std::size_t>(r)])]);
    }
    return i;
  };
  out.triangles.reserve(part.corners.size());
  for (std::size_t k = 0; k < part.corners.size(); ++k) {
    const Eigen::Vector3i& t = part.corners[k];
    const Eigen::Vector3i w(vertex(t[0]), vertex(t[1]), vertex(t[2]));
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;
    out.triangles.push_back(w);
    if (source != nullptr) source->push_back(part.face[k]);
  }
  return out;
}

// Signed crossings of the ray from `p` along a fixed, slightly skewed
// direction with the triangles of one component: the winding number of the
// component about `p` (+1 inside an outward component, -1 inside an inward
// one, 0 outside).
int winding_number(const Mesh& m, const std::vector<int>& faces, const Eigen::Vector3d& p) {
  const Eigen::Vector3d dir = Eigen::Vector3d(1.0, 0.0123456789, 0.00314159265).normalized();
  int w = 0;
  for (int f : faces) {
    const Eigen::Vector3i& t = m.triangles[static_cast<std::size_t>(f)];
    const Eigen::Vector3d a = m.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d e1 = m.positions[static_cast<std::size_t>(t[1])].cast<double>() - a;
    const Eigen::Vector3d e2 = m.positions[static_cast<std::size_t>(t[2])].cast<double>() - a;
    const Eigen::Vector3d q = dir.cross(e2);
    const double det = e1.dot(q);
    if (det == 0.0) continue;
    const Eigen::Vector3d s = p - a;
    const double u = s.dot(q) / det;
    if (u < 0.0 || u > 1.0) continue;
    const Eigen::Vector3d r = s.cross(e1);
    const double v = dir.dot(r) / det;
    if (v < 0.0 || u + v > 1.0) continue;
    if (e2.dot(r) / det <= 0.0) continue;  // behind p
    // The ray leaves through a face whose normal (e1 x e2) points along it.
    w += e1.cross(e2).dot(dir) > 0.0 ? 1 : -1;
  }
  return w;
}

double signed_volume_of(const Mesh& m, const std::vector<int>& faces) {
  double six_v = 0.0;
  for (int f : faces) {
    const Eigen::Vector3i& t = m.triangles[static_cast<std::size_t>(f)];
    const Eigen::Vector3d a = m.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = m.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = m.positions[static_cast<std::size_t>(t[2])].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

// Whether every directed edge occurs once and its reverse once: the cheap
// test that turns most open parts away before the full checks.
bool edges_pair_up(const Mesh& m) {
  std::vector<std::uint64_t> edges;
  edges.reserve(static_cast<std::size_t>(m.num_faces()) * 3);
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e)
      edges.push_back((static_cast<std::uint64_t>(static_cast<std::uint32_t>(t[e])) << 32) |
                      static_cast<std::uint32_t>(t[(e + 1) % 3]));
  tbb::parallel_sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  // Without repeats, every edge's reverse is present exactly when the
  // reversed edges are the same set: one more sort, not a search per edge.
  std::vector<std::uint64_t> reversed(edges.size());
  std::transform(edges.begin(), edges.end(), reversed.begin(), [](std::uint64_t e) { return (e << 32) | (e >> 32); });
  tbb::parallel_sort(reversed.begin(), reversed.end());
  return reversed == edges;
}

// Orients every component so that the winding number is 0 or 1 on both
// sides of it; false when no orientation does (overlapping solids).
// `turned` says whether any component was turned.
bool orient_components(Mesh& m, bool& turned) {
  const int nv = m.num_vertices();
  detail::UnionFind sets(static_cast<std::size_t>(nv));
  for (const auto& t : m.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[1], t[2]);
  }
  std::unordered_map<int, int> component_of_root;
  std::vector<std::vector<int>> faces;
  for (int f = 0; f < m.num_faces(); ++f) {
    const int root = sets.find(m.triangles[static_cast<std::size_t>(f)][0]);
    auto [it, inserted] = component_of_root.emplace(root, static_cast<int>(faces.size()));
    if (inserted) faces.emplace_back();
    faces[static_cast<std::size_t>(it->second)].push_back(f);
  }
  const std::size_t nc = faces.size();
  std::vector<int> sign(nc);
  std::vector<Eigen::AlignedBox3d> box(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    sign[c] = signed_volume_of(m, faces[c]) >= 0.0 ? 1 : -1;
    for (int f : faces[c])
      for (int k = 0; k < 3; ++k)
        box[c].extend(
            m.positions[static_cast<std::size_t>(m.triangles[static_cast<std::size_t>(f)][k])].cast<double>());
  }
  // The winding number just outside each component, from the others: it
  // does not depend on how the component itself is turned.
  std::vector<int> outside(nc, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const Eigen::Vector3d p =
        m.positions[static_cast<std::size_t>(m.triangles[static_cast<std::size_t>(faces[c][0])][0])].cast<double>();
    for (std::size_t d = 0; d < nc; ++d)
      if (d != c && box[d].contains(p)) outside[c] += winding_number(m, faces[d], p);
  }
  // Turning a component flips its contribution to every other's `outside`,
  // so components are decided outermost first (fewest enclosing).
  std::vector<std::size_t> order(nc);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return std::abs(outside[a]) < std::abs(outside[b]); });
  bool any_turned = false;
  turned = false;
  for (std::size_t c : order) {
    int w = 0;  // recomputed from the current orientation of the others
    const Eigen::Vector3d p =
        m.positions[static_cast<std::size_t>(m.triangles[static_cast<std::size_t>(faces[c][0])][0])].cast<double>();
    if (any_turned) {
      for (std::size_t d = 0; d < nc; ++d)
        if (d != c && box[d].contains(p)) w += winding_number(m, faces[d], p);
    } else {
      w = outside[c];
    }
    if (w != 0 && w != 1) return false;
    const int wanted = w == 0 ? 1 : -1;  // outward in empty space, inward inside a solid (a cavity)
    if (sign[c] != wanted) {
      // Inside another component, the wrong way round is ambiguous: a cavity
      // wound the wrong way, or a second solid overlapping the first.
      if (w != 0) return false;
      for (int f : faces[c])
        std::swap(m.triangles[static_cast<std::size_t>(f)][1], m.triangles[static_cast<std::size_t>(f)][2]);
      sign[c] = wanted;
      any_turned = turned = true;
    }
  }
  return true;
}

}  // namespace

double detail::weld_distance(const Mesh& mesh, double weld_tolerance) {
  return std::max(0.0, weld_tolerance) * bounds(mesh).diagonal().norm();
}

Mesh detail::welded_part_faces(const Mesh& mesh, const Part& part, double weld_distance_m, std::vector<int>* source) {
  if (source != nullptr) source->clear();
  if (part.faces.empty() || mesh.num_faces() == 0) return {};
  const LocalFaces local = local_faces(mesh, part);
  return welded_part(mesh, local, weld(mesh, local, weld_distance_m), source);
}

Mesh detail::closed_part_surface_checked(const Mesh& mesh, const Part& part, double weld_distance_m,
                                         MeshChecks& checks) {
  checks = MeshChecks();
  Mesh closed = detail::welded_part_faces(mesh, part, weld_distance_m);
  if (closed.num_faces() < 4 || !edges_pair_up(closed)) return {};
  checks = check_closed_mesh(closed);
  // Closed and oriented within each component; orientation between
  // components is decided below.
  if (!checks.closed || !checks.manifold || (checks.self_intersections_checked && !checks.self_intersection_free))
    return {};
  bool turned = false;
  if (!orient_components(closed, turned)) return {};
  if (turned) checks = check_closed_mesh(closed);
  if (!checks.watertight()) return {};
  return closed;
}

Mesh closed_part_surface(const Mesh& mesh, const Part& part, double weld_tolerance) {
  MeshChecks checks;
  return detail::closed_part_surface_checked(mesh, part, detail::weld_distance(mesh, weld_tolerance), checks);
}

}  // namespace g2p
