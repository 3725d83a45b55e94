// Parts: connected components of same-label faces; small fragments merge into
// the neighbouring part they share the longest border with.
#include <algorithm>
#include <numeric>

#include "g2p/project.h"

namespace g2p {
namespace {

// Components of same-label faces; returns the number of parts.
int components(const FaceGraph& graph, const std::vector<int>& labels, std::vector<int>& face_part) {
  const int nf = graph.num_faces();
  face_part.assign(static_cast<std::size_t>(nf), -1);
  int parts = 0;
  std::vector<int> queue;
  for (int seed = 0; seed < nf; ++seed) {
    if (face_part[static_cast<std::size_t>(seed)] >= 0) continue;
    face_part[static_cast<std::size_t>(seed)] = parts;
    queue.assign(1, seed);
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int f = queue[q];
      for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
        const int g = graph.neighbors[static_cast<std::size_t>(i)];
        if (face_part[static_cast<std::size_t>(g)] < 0 &&
            labels[static_cast<std::size_t>(g)] == labels[static_cast<std::size_t>(f)]) {
          face_part[static_cast<std::size_t>(g)] = parts;
          queue.push_back(g);
        }
      }
    }
    ++parts;
  }
  return parts;
}

}  // namespace

std::vector<Part> partition(const Mesh& mesh, const FaceGraph& graph, std::vector<int>& labels,
                            std::vector<int>& face_part, const PartitionOptions& options,
                            const std::vector<float>* confidence) {
  if (confidence != nullptr && confidence->size() != static_cast<std::size_t>(mesh.num_faces())) confidence = nullptr;
  const int nf = mesh.num_faces();
  std::vector<double> area(static_cast<std::size_t>(nf));
  double total = 0.0;
  for (int f = 0; f < nf; ++f) total += area[static_cast<std::size_t>(f)] = face_area(mesh, f);
  const double threshold = std::max(0.0, options.min_part_area_fraction) * total;

  int parts = components(graph, labels, face_part);
  for (int pass = 0; pass < 16 && threshold > 0.0; ++pass) {
    std::vector<double> part_area(static_cast<std::size_t>(parts), 0.0), part_confidence(part_area.size(), 0.0);
    for (int f = 0; f < nf; ++f) {
      part_area[static_cast<std::size_t>(face_part[f])] += area[static_cast<std::size_t>(f)];
      if (confidence != nullptr)
        part_confidence[static_cast<std::size_t>(face_part[f])] +=
            area[static_cast<std::size_t>(f)] * (*confidence)[static_cast<std::size_t>(f)];
    }
    std::vector<int> small;
    for (int p = 0; p < parts; ++p) {
      const double a = part_area[static_cast<std::size_t>(p)];
      const bool confident = confidence != nullptr && a > 0.0 &&
                             part_confidence[static_cast<std::size_t>(p)] / a > options.merge_max_confidence;
      if (a < threshold && !confident) small.push_back(p);
    }
    if (small.empty()) break;
    // Smallest first; a fragment merges into its neighbour as that is now.
    std::stable_sort(small.begin(), small.end(), [&](int a, int b) { return part_area[a] < part_area[b]; });
    std::vector<std::vector<int>> faces_of(static_cast<std::size_t>(parts));
    for (int f = 0; f < nf; ++f) faces_of[static_cast<std::size_t>(face_part[f])].push_back(f);
    bool merged = false;
    for (int p : small) {
      std::vector<std::pair<int, double>> border;  // neighbour part, shared length
      for (int f : faces_of[static_cast<std::size_t>(p)]) {
        for (int i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
          const int q = face_part[static_cast<std::size_t>(graph.neighbors[static_cast<std::size_t>(i)])];
          if (q == p) continue;
          auto it = std::find_if(border.begin(), border.end(), [q](const auto& e) { return e.first == q; });
          if (it == border.end())
            border.emplace_back(q, graph.shared_edge_m[static_cast<std::size_t>(i)]);
          else
            it->second += graph.shared_edge_m[static_cast<std::size_t>(i)];
        }
      }
      if (border.empty()) continue;  // an isolated fragment keeps its label
      const auto target = *std::max_element(border.begin(), border.end(), [](const auto& a, const auto& b) {
        return a.second != b.second ? a.second < b.second : a.first > b.first;
      });
      const int new_label = labels[static_cast<std::size_t>(faces_of[static_cast<std::size_t>(target.first)].front())];
      for (int f : faces_of[static_cast<std::size_t>(p)]) {
        labels[static_cast<std::size_t>(f)] = new_label;
        face_part[static_cast<std::size_t>(f)] = target.first;
      }
      faces_of[static_cast<std::size_t>(target.first)].insert(faces_of[static_cast<std::size_t>(target.first)].end(),
                                                              faces_of[static_cast<std::size_t>(p)].begin(),
                                                              faces_of[static_cast<std::size_t>(p)].end());
      faces_of[static_cast<std::size_t>(p)].clear();
      merged = true;
    }
    if (!merged) break;
    parts = components(graph, labels, face_part);
  }

  std::vector<Part> out(static_cast<std::size_t>(parts));
  for (int f = 0; f < nf; ++f) {
    Part& part = out[static_cast<std::size_t>(face_part[f])];
    part.label = labels[static_cast<std::size_t>(f)];
    part.faces.push_back(f);
    part.area_m2 += area[static_cast<std::size_t>(f)];
  }
  return out;
}

}  // namespace g2p
