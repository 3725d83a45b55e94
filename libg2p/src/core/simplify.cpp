#include "core/simplify.h"

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

// Edge collapses on a closed mesh, in place: positions in double, faces
// marked dead rather than removed, each vertex with its faces, its quadric and
// the quadric's weight, and candidate collapses in a heap by cost.
class EdgeCollapser {
 public:
  EdgeCollapser(Mesh& mesh, double max_error_m)
      : faces_(mesh.triangles),
        nv_(mesh.num_vertices()),
        nf_(mesh.num_faces()),
        max_cost_(max_error_m * max_error_m),
        pos_(static_cast<std::size_t>(nv_)),
        face_alive_(static_cast<std::size_t>(nf_), 1),
        vertex_alive_(static_cast<std::size_t>(nv_), 1),
        vf_(static_cast<std::size_t>(nv_)),
        quadric_(static_cast<std::size_t>(nv_), Eigen::Matrix4d::Zero()),
        weight_(static_cast<std::size_t>(nv_), 0.0),
        stamp_(static_cast<std::size_t>(nv_), 0) {
    for (int v = 0; v < nv_; ++v)
      pos_[static_cast<std::size_t>(v)] = mesh.positions[static_cast<std::size_t>(v)].cast<double>();
    accumulate_quadrics();
    for (int f = 0; f < nf_; ++f) {
      const Eigen::Vector3i& t = faces_[static_cast<std::size_t>(f)];
      for (int e = 0; e < 3; ++e)
        if (t[e] < t[(e + 1) % 3]) evaluate(t[e], t[(e + 1) % 3]);
    }
  }

  // Collapses the cheapest edges while their cost stays within the bound and
  // more than four faces are left; returns how many.
  int collapse_edges() {
    int collapses = 0, live_faces = nf_;
    while (!heap_.empty() && live_faces > 4) {
      const Candidate c = heap_.top();
      heap_.pop();
      const auto u = static_cast<std::size_t>(c.u), v = static_cast<std::size_t>(c.v);
      if (!vertex_alive_[u] || !vertex_alive_[v] || stamp_[u] != c.stamp_u || stamp_[v] != c.stamp_v) continue;
      if (!link_condition_and_valence(c.u, c.v) || !keeps_triangles(c)) continue;
      live_faces -= collapse(c);
      ++collapses;
      // Only the edges at u changed cost; the others' candidates stay valid
      // (the link and flip conditions are checked again when they come up).
      ring(c.u, ring_u_);
      for (int w : ring_u_) evaluate(std::min(c.u, w), std::max(c.u, w));
    }
    return collapses;
  }

  // The live faces with their vertices, compacted.
  Mesh compacted() const {
    std::vector<int> remap(static_cast<std::size_t>(nv_), -1);
    Mesh out;
    for (int f = 0; f < nf_; ++f) {
      if (!face_alive_[static_cast<std::size_t>(f)]) continue;
      Eigen::Vector3i t = faces_[static_cast<std::size_t>(f)];
      for (int k = 0; k < 3; ++k) {
        int& r = remap[static_cast<std::size_t>(t[k])];
        if (r < 0) {
          r = out.num_vertices();
          out.positions.push_back(pos_[static_cast<std::size_t>(t[k])].cast<float>());
        }
        t[k] = r;
      }
      out.triangles.push_back(t);
    }
    return out;
  }

 private:
  Eigen::Vector3d normal_of(const Eigen::Vector3i& t) const {
    return (pos_[static_cast<std::size_t>(t[1])] - pos_[static_cast<std::size_t>(t[0])])
        .cross(pos_[static_cast<std::size_t>(t[2])] - pos_[static_cast<std::size_t>(t[0])]);
  }

  // Every vertex's faces, and its quadric: the area-weighted planes of its
  // faces. Errors are compared as squared distances by dividing by the weight
  // (the summed areas) of the merged quadric.
  void accumulate_quadrics() {
    for (int f = 0; f < nf_; ++f) {
      const Eigen::Vector3i& t = faces_[static_cast<std::size_t>(f)];
      Eigen::Vector3d n = normal_of(t);
      const double area2 = n.norm();
      for (int c = 0; c < 3; ++c) vf_[static_cast<std::size_t>(t[c])].push_back(f);
      if (!(area2 > 0)) continue;
      n /= area2;
      Eigen::Vector4d plane(n.x(), n.y(), n.z(), -n.dot(pos_[static_cast<std::size_t>(t[0])]));
      const Eigen::Matrix4d q = plane * plane.transpose() * area2;  // area-weighted
      for (int c = 0; c < 3; ++c) quadric_[static_cast<std::size_t>(t[c])] += q;
    }
    for (int f = 0; f < nf_; ++f) {
      const double a = normal_of(faces_[static_cast<std::size_t>(f)]).norm();
      for (int c = 0; c < 3; ++c) weight_[static_cast<std::size_t>(faces_[static_cast<std::size_t>(f)][c])] += a;
    }
  }

  // Queues the collapse of edge (u, v) to the cheapest of the merged
  // quadric's minimiser, the edge's midpoint and its ends, if it costs at
  // most max_cost_.
  void evaluate(int u, int v) {
    const Eigen::Matrix4d q = quadric_[static_cast<std::size_t>(u)] + quadric_[static_cast<std::size_t>(v)];
    const double w = std::max(weight_[static_cast<std::size_t>(u)] + weight_[static_cast<std::size_t>(v)], 1e-300);
    auto cost_at = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector4d h(p.x(), p.y(), p.z(), 1.0);
      return h.dot(q * h) / w;
    };
    const Eigen::Vector3d& pu = pos_[static_cast<std::size_t>(u)];
    const Eigen::Vector3d& pv = pos_[static_cast<std::size_t>(v)];
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
    if (best_cost <= max_cost_)
      heap_.push({best_cost, u, v, stamp_[static_cast<std::size_t>(u)], stamp_[static_cast<std::size_t>(v)], best});
  }

  // The vertices sharing a live face with x, sorted.
  void ring(int x, std::vector<int>& out) const {
    out.clear();
    for (int f : vf_[static_cast<std::size_t>(x)]) {
      if (!face_alive_[static_cast<std::size_t>(f)]) continue;
      for (int c = 0; c < 3; ++c)
        if (faces_[static_cast<std::size_t>(f)][c] != x) out.push_back(faces_[static_cast<std::size_t>(f)][c]);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // Link condition: u and v share exactly the two opposite vertices. And the
  // valences stay small: fans of slivers are slow to process and fold easily.
  bool link_condition_and_valence(int u, int v) {
    ring(u, ring_u_);
    ring(v, ring_v_);
    if (!std::binary_search(ring_u_.begin(), ring_u_.end(), v)) return false;
    int shared = 0;
    for (int x : ring_u_) shared += std::binary_search(ring_v_.begin(), ring_v_.end(), x);
    if (shared != 2) return false;
    return ring_u_.size() + ring_v_.size() <= 4 + 12;
  }

  // No surviving triangle at u or v flips, turns by more than 60 degrees or
  // collapses when its vertex moves to the candidate's position.
  bool keeps_triangles(const Candidate& c) {
    for (auto x : {static_cast<std::size_t>(c.u), static_cast<std::size_t>(c.v)}) {
      for (int f : vf_[x]) {
        if (!face_alive_[static_cast<std::size_t>(f)]) continue;
        Eigen::Vector3i t = faces_[static_cast<std::size_t>(f)];
        const bool has_u = t[0] == c.u || t[1] == c.u || t[2] == c.u;
        const bool has_v = t[0] == c.v || t[1] == c.v || t[2] == c.v;
        if (has_u && has_v) continue;  // removed by the collapse
        const Eigen::Vector3d before = normal_of(t);
        const Eigen::Vector3d saved = pos_[x];
        pos_[x] = c.position;
        const Eigen::Vector3d after = normal_of(t);
        pos_[x] = saved;
        if (!(after.norm() > 1e-12 * before.norm()) || after.dot(before) < 0.5 * after.norm() * before.norm())
          return false;
      }
    }
    return true;
  }

  // Collapses v into u at the candidate's position; returns how many faces died.
  int collapse(const Candidate& c) {
    const auto u = static_cast<std::size_t>(c.u), v = static_cast<std::size_t>(c.v);
    int removed = 0;
    pos_[u] = c.position;
    for (int f : vf_[v]) {
      if (!face_alive_[static_cast<std::size_t>(f)]) continue;
      Eigen::Vector3i& t = faces_[static_cast<std::size_t>(f)];
      if (t[0] == c.u || t[1] == c.u || t[2] == c.u) {
        face_alive_[static_cast<std::size_t>(f)] = 0;
        ++removed;
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (t[k] == c.v) t[k] = c.u;
      vf_[u].push_back(f);
    }
    vf_[u].erase(
        std::remove_if(vf_[u].begin(), vf_[u].end(), [&](int f) { return !face_alive_[static_cast<std::size_t>(f)]; }),
        vf_[u].end());
    vf_[v].clear();
    vertex_alive_[v] = 0;
    quadric_[u] += quadric_[v];
    weight_[u] += weight_[v];
    ++stamp_[u];
    return removed;
  }

  std::vector<Eigen::Vector3i>& faces_;  // the mesh's triangles, rewritten by the collapses
  const int nv_, nf_;
  const double max_cost_;  // squared distance, m^2
  std::vector<Eigen::Vector3d> pos_;
  std::vector<char> face_alive_, vertex_alive_;
  std::vector<std::vector<int>> vf_;  // faces at each vertex (dead ones dropped when the vertex collapses)
  std::vector<Eigen::Matrix4d> quadric_;
  std::vector<double> weight_;
  std::vector<unsigned> stamp_;  // bumped by every collapse into the vertex; older candidates are stale
  std::priority_queue<Candidate> heap_;
  std::vector<int> ring_u_, ring_v_;
};

}  // namespace

int simplify_closed_mesh(Mesh& mesh, double max_error_m) {
  if (mesh.num_faces() < 8 || !(max_error_m > 0)) return 0;
  EdgeCollapser collapser(mesh, max_error_m);
  const int collapses = collapser.collapse_edges();
  mesh = collapser.compacted();
  return collapses;
}

}  // namespace g2p::detail
