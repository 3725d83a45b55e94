#include "complete/simplify.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <queue>
#include <vector>

namespace g2p::detail {
namespace {

struct Candidate {
  double cost;
  int u, v;
  unsigned stamp_u, stamp_v;
  Eigen::Vector3d position;
  bool operator<(const Candidate& o) const { return cost > o.cost; }  // min-heap
};

}  // namespace

int simplify_closed_mesh(Mesh& mesh, double max_error_m) {
  const int nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (nf < 8 || !(max_error_m > 0)) return 0;
  std::vector<Eigen::Vector3d> pos(static_cast<std::size_t>(nv));
  for (int v = 0; v < nv; ++v)
    pos[static_cast<std::size_t>(v)] = mesh.positions[static_cast<std::size_t>(v)].cast<double>();
  std::vector<Eigen::Vector3i>& faces = mesh.triangles;
  std::vector<char> face_alive(static_cast<std::size_t>(nf), 1), vertex_alive(static_cast<std::size_t>(nv), 1);
  std::vector<std::vector<int>> vf(static_cast<std::size_t>(nv));
  std::vector<Eigen::Matrix4d> quadric(static_cast<std::size_t>(nv), Eigen::Matrix4d::Zero());
  std::vector<unsigned> stamp(static_cast<std::size_t>(nv), 0);
  auto normal_of = [&](const Eigen::Vector3i& t) {
    return (pos[static_cast<std::size_t>(t[1])] - pos[static_cast<std::size_t>(t[0])])
        .cross(pos[static_cast<std::size_t>(t[2])] - pos[static_cast<std::size_t>(t[0])]);
  };
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = faces[static_cast<std::size_t>(f)];
    Eigen::Vector3d n = normal_of(t);
    const double area2 = n.norm();
    for (int c = 0; c < 3; ++c) vf[static_cast<std::size_t>(t[c])].push_back(f);
    if (!(area2 > 0)) continue;
    n /= area2;
    Eigen::Vector4d plane(n.x(), n.y(), n.z(), -n.dot(pos[static_cast<std::size_t>(t[0])]));
    const Eigen::Matrix4d q = plane * plane.transpose() * area2;  // area-weighted
    for (int c = 0; c < 3; ++c) quadric[static_cast<std::size_t>(t[c])] += q;
  }
  // Quadrics are area-weighted; compare errors as squared distances by
  // dividing by the weight (the summed areas) of the merged quadric.
  std::vector<double> weight(static_cast<std::size_t>(nv), 0.0);
  for (int f = 0; f < nf; ++f) {
    const double a = normal_of(faces[static_cast<std::size_t>(f)]).norm();
    for (int c = 0; c < 3; ++c) weight[static_cast<std::size_t>(faces[static_cast<std::size_t>(f)][c])] += a;
  }
  const double max_cost = max_error_m * max_error_m;

  std::priority_queue<Candidate> heap;
  auto evaluate = [&](int u, int v) {
    const Eigen::Matrix4d q = quadric[static_cast<std::size_t>(u)] + quadric[static_cast<std::size_t>(v)];
    const double w = std::max(weight[static_cast<std::size_t>(u)] + weight[static_cast<std::size_t>(v)], 1e-300);
    auto cost_at = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector4d h(p.x(), p.y(), p.z(), 1.0);
      return h.dot(q * h) / w;
    };
    const Eigen::Vector3d& pu = pos[static_cast<std::size_t>(u)];
    const Eigen::Vector3d& pv = pos[static_cast<std::size_t>(v)];
    Eigen::Vector3d best = 0.5 * (pu + pv);
    double best_cost = cost_at(best);
    // The quadric's minimiser, if well conditioned and near the edge.
    const Eigen::Matrix3d a = q.topLeftCorner<3, 3>();
    const double det = a.determinant();
    if (std::abs(det) > 1e-9 * std::pow(a.norm(), 3)) {
      const Eigen::Vector3d p = a.inverse() * (-q.topRightCorner<3, 1>());
      if ((p - best).norm() <= (pu - pv).norm()) {
        const double c = cost_at(p);
        if (c < best_cost) best = p, best_cost = c;
      }
    }
    for (const Eigen::Vector3d* p : {&pu, &pv}) {
      const double c = cost_at(*p);
      if (c < best_cost) best = *p, best_cost = c;
    }
    if (best_cost <= max_cost)
      heap.push({best_cost, u, v, stamp[static_cast<std::size_t>(u)], stamp[static_cast<std::size_t>(v)], best});
  };
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = faces[static_cast<std::size_t>(f)];
    for (int e = 0; e < 3; ++e)
      if (t[e] < t[(e + 1) % 3]) evaluate(t[e], t[(e + 1) % 3]);
  }

  std::vector<int> ring_u, ring_v;
  auto ring = [&](int x, std::vector<int>& out) {
    out.clear();
    for (int f : vf[static_cast<std::size_t>(x)]) {
      if (!face_alive[static_cast<std::size_t>(f)]) continue;
      for (int c = 0; c < 3; ++c)
        if (faces[static_cast<std::size_t>(f)][c] != x) out.push_back(faces[static_cast<std::size_t>(f)][c]);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };
  int collapses = 0, live_faces = nf;
  while (!heap.empty() && live_faces > 4) {
    const Candidate c = heap.top();
    heap.pop();
    const auto u = static_cast<std::size_t>(c.u), v = static_cast<std::size_t>(c.v);
    if (!vertex_alive[u] || !vertex_alive[v] || stamp[u] != c.stamp_u || stamp[v] != c.stamp_v) continue;
    // Link condition: the two vertices share exactly the two opposite vertices.
    ring(c.u, ring_u);
    ring(c.v, ring_v);
    if (!std::binary_search(ring_u.begin(), ring_u.end(), c.v)) continue;
    int shared = 0;
    for (int x : ring_u) shared += std::binary_search(ring_v.begin(), ring_v.end(), x);
    if (shared != 2) continue;
    // Keep valences small: fans of slivers are slow to process and fold easily.
    if (ring_u.size() + ring_v.size() > 4 + 12) continue;
    // No surviving triangle may flip or collapse.
    bool ok = true;
    for (std::size_t x : {u, v}) {
      for (int f : vf[x]) {
        if (!face_alive[static_cast<std::size_t>(f)]) continue;
        Eigen::Vector3i t = faces[static_cast<std::size_t>(f)];
        const bool has_u = t[0] == c.u || t[1] == c.u || t[2] == c.u;
        const bool has_v = t[0] == c.v || t[1] == c.v || t[2] == c.v;
        if (has_u && has_v) continue;  // removed by the collapse
        const Eigen::Vector3d before = normal_of(t);
        const Eigen::Vector3d saved = pos[x];
        pos[x] = c.position;
        const Eigen::Vector3d after = normal_of(t);
        pos[x] = saved;
        if (!(after.norm() > 1e-12 * before.norm()) || after.dot(before) < 0.5 * after.norm() * before.norm()) {
          ok = false;
          break;
        }
      }
      if (!ok) break;
    }
    if (!ok) continue;
    // Collapse v into u.
    pos[u] = c.position;
    for (int f : vf[v]) {
      if (!face_alive[static_cast<std::size_t>(f)]) continue;
      Eigen::Vector3i& t = faces[static_cast<std::size_t>(f)];
      if (t[0] == c.u || t[1] == c.u || t[2] == c.u) {
        face_alive[static_cast<std::size_t>(f)] = 0;
        --live_faces;
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (t[k] == c.v) t[k] = c.u;
      vf[u].push_back(f);
    }
    vf[u].erase(
        std::remove_if(vf[u].begin(), vf[u].end(), [&](int f) { return !face_alive[static_cast<std::size_t>(f)]; }),
        vf[u].end());
    vf[v].clear();
    vertex_alive[v] = 0;
    quadric[u] += quadric[v];
    weight[u] += weight[v];
    ++stamp[u];
    ++collapses;
    // Only the edges at u changed cost; the others' candidates stay valid
    // (the link and flip conditions are checked again when they come up).
    ring(c.u, ring_u);
    for (int w : ring_u) evaluate(std::min(c.u, w), std::max(c.u, w));
  }

  // Compact.
  std::vector<int> remap(static_cast<std::size_t>(nv), -1);
  Mesh out;
  for (int f = 0; f < nf; ++f) {
    if (!face_alive[static_cast<std::size_t>(f)]) continue;
    Eigen::Vector3i t = faces[static_cast<std::size_t>(f)];
    for (int k = 0; k < 3; ++k) {
      int& r = remap[static_cast<std::size_t>(t[k])];
      if (r < 0) {
        r = out.num_vertices();
        out.positions.push_back(pos[static_cast<std::size_t>(t[k])].cast<float>());
      }
      t[k] = r;
    }
    out.triangles.push_back(t);
  }
  mesh = std::move(out);
  return collapses;
}

}  // namespace g2p::detail
