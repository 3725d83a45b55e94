// Face labels from votes, and the flood fill of faces no view saw.
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "g2p/project.h"

namespace g2p {
namespace {

// Nearest labelled face centroid, on a uniform grid of the labelled centroids.
class CentroidGrid {
 public:
  // A grid over the box of all `points` (so every query from the same mesh
  // lies inside it) holding the points `ids`.
  CentroidGrid(const std::vector<Eigen::Vector3f>& points, const std::vector<int>& ids) : points_(points) {
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& p : points) box.extend(p);
    origin_ = box.min();
    const float extent = std::max(box.sizes().maxCoeff(), 1e-9f);
    cells_per_axis_ = std::max(1, static_cast<int>(std::cbrt(static_cast<double>(ids.size()))));
    cell_ = extent / cells_per_axis_ * (1.f + 1e-6f);
    for (int i : ids) cells_[key(cell_of(points[static_cast<std::size_t>(i)]))].push_back(i);
  }

  // Index of the nearest point, or -1 if the grid is empty.
  int nearest(const Eigen::Vector3f& q, float* distance) const {
    const Eigen::Vector3i c = cell_of(q);
    int best = -1;
    float best_d2 = std::numeric_limits<float>::infinity();
    for (int ring = 0; ring <= cells_per_axis_ + 1; ++ring) {
      // Once a point is found, rings beyond its distance cannot hold a nearer one.
      if (best >= 0 && (ring - 1) * cell_ > std::sqrt(best_d2)) break;
      for (int dz = -ring; dz <= ring; ++dz)
        for (int dy = -ring; dy <= ring; ++dy)
          for (int dx = -ring; dx <= ring; ++dx) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != ring) continue;
            const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
            if (it == cells_.end()) continue;
            for (int i : it->second) {
              const float d2 = (points_[static_cast<std::size_t>(i)] - q).squaredNorm();
              if (d2 < best_d2 || (d2 == best_d2 && i < best)) best_d2 = d2, best = i;
            }
          }
    }
    if (distance != nullptr) *distance = std::sqrt(best_d2);
    return best;
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const {
    return ((p - origin_) / cell_).array().floor().cast<int>();
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x()) & 0x1FFFFF) | ((static_cast<std::uint64_t>(c.y()) & 0x1FFFFF) << 21) |
           ((static_cast<std::uint64_t>(c.z()) & 0x1FFFFF) << 42);
  }
  const std::vector<Eigen::Vector3f>& points_;
  Eigen::Vector3f origin_;
  float cell_ = 1.f;
  int cells_per_axis_ = 1;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

}  // namespace

FaceLabels assign_labels(const Mesh& mesh, const FaceGraph& graph, const FaceVotes& votes) {
  const int nf = mesh.num_faces();
  const int k = votes.num_classes;
  FaceLabels out;
  out.label.assign(static_cast<std::size_t>(nf), kUnknownLabel);
  out.confidence.assign(static_cast<std::size_t>(nf), 0.f);
  out.seen.assign(static_cast<std::size_t>(nf), 0);
  for (int f = 0; f < nf; ++f) {
    const float total = votes.total[static_cast<std::size_t>(f)];
    const float* h = votes.of(f);
    if (h == nullptr || !(total > 0.f)) continue;
    int best = 0;
    for (int c = 1; c < k; ++c)
      if (h[c] > h[best]) best = c;  // strict: ties keep the lower index
    out.label[static_cast<std::size_t>(f)] = best;
    out.confidence[static_cast<std::size_t>(f)] = h[best] / total;
    out.seen[static_cast<std::size_t>(f)] = 1;
  }

  // Waves of majority votes among labelled neighbours. Each wave reads only
  // labels set before it, so the result does not depend on face order.
  std::vector<int>& label = out.label;
  std::vector<int> frontier;
  for (int f = 0; f < nf; ++f) {
    if (label[static_cast<std::size_t>(f)] != kUnknownLabel) continue;
    for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i)
      if (label[static_cast<std::size_t>(graph.neighbors[static_cast<std::size_t>(i)])] != kUnknownLabel) {
        frontier.push_back(f);
        break;
      }
  }
  std::vector<int> count(static_cast<std::size_t>(k)), next_frontier;
  std::vector<float> border(static_cast<std::size_t>(k));
  std::vector<std::pair<int, int>> assigned;
  std::vector<std::uint8_t> queued(static_cast<std::size_t>(nf), 0);
  while (!frontier.empty()) {
    assigned.clear();
    for (int f : frontier) {
      std::fill(count.begin(), count.end(), 0);
      std::fill(border.begin(), border.end(), 0.f);
      for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
        const int l = label[static_cast<std::size_t>(graph.neighbors[static_cast<std::size_t>(i)])];
        if (l == kUnknownLabel) continue;
        ++count[static_cast<std::size_t>(l)];
        border[static_cast<std::size_t>(l)] += graph.shared_edge_m[static_cast<std::size_t>(i)];
      }
      int best = -1;
      for (int c = 0; c < k; ++c) {
        if (count[c] == 0) continue;
        if (best < 0 || count[c] > count[best] || (count[c] == count[best] && border[c] > border[best])) best = c;
      }
      if (best >= 0) assigned.emplace_back(f, best);
    }
    next_frontier.clear();
    for (const auto& [f, l] : assigned) label[static_cast<std::size_t>(f)] = l;
    for (const auto& [f, l] : assigned) {
      for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
        const int g = graph.neighbors[static_cast<std::size_t>(i)];
        if (label[static_cast<std::size_t>(g)] == kUnknownLabel && !queued[static_cast<std::size_t>(g)]) {
          queued[static_cast<std::size_t>(g)] = 1;
          next_frontier.push_back(g);
        }
      }
    }
    for (int g : next_frontier) queued[static_cast<std::size_t>(g)] = 0;
    std::sort(next_frontier.begin(), next_frontier.end());
    frontier.swap(next_frontier);
  }

  // Components no label reached: the label of the nearest labelled face.
  std::vector<int> labelled, unlabelled;
  for (int f = 0; f < nf; ++f)
    (label[static_cast<std::size_t>(f)] == kUnknownLabel ? unlabelled : labelled).push_back(f);
  if (unlabelled.empty() || labelled.empty()) return out;
  std::vector<Eigen::Vector3f> centroid(static_cast<std::size_t>(nf));
  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(f)];
    centroid[static_cast<std::size_t>(f)] = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.f;
  }
  const CentroidGrid grid(centroid, labelled);
  std::vector<int> component;
  for (int seed : unlabelled) {
    if (label[static_cast<std::size_t>(seed)] != kUnknownLabel) continue;
    // Gather the component (its faces are all unlabelled), then find its nearest labelled face.
    component.assign(1, seed);
    label[static_cast<std::size_t>(seed)] = -2;  // visiting
    for (std::size_t q = 0; q < component.size(); ++q) {
      const int f = component[q];
      for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
        const int g = graph.neighbors[static_cast<std::size_t>(i)];
        if (label[static_cast<std::size_t>(g)] == kUnknownLabel) {
          label[static_cast<std::size_t>(g)] = -2;
          component.push_back(g);
        }
      }
    }
    int nearest = -1;
    float nearest_d = std::numeric_limits<float>::infinity();
    for (int f : component) {
      float d = 0.f;
      const int n = grid.nearest(centroid[static_cast<std::size_t>(f)], &d);
      if (n >= 0 && (d < nearest_d || (d == nearest_d && n < nearest))) nearest = n, nearest_d = d;
    }
    for (int f : component) label[static_cast<std::size_t>(f)] = label[static_cast<std::size_t>(nearest)];
  }
  return out;
}

}  // namespace g2p
