// The project stage end to end, and face labels seen through a view.
#include "g2p/project.h"

namespace g2p {

Result<Projection> project(const Mesh& mesh, const std::vector<View>& views, const std::vector<LabelMap>& maps,
                           int num_classes, const ProjectOptions& options) {
  Projection p;
  Result<FaceGraph> graph = build_face_graph(mesh, options.weld_tolerance);
  if (!graph.ok()) return graph.status();
  p.graph = std::move(*graph);
  Result<FaceVotes> votes = vote(mesh, views, maps, num_classes, options.vote);
  if (!votes.ok()) return votes.status();
  p.votes = std::move(*votes);
  p.labels = assign_labels(mesh, p.graph, p.votes);
  const std::vector<float> voted_confidence = p.labels.confidence;
  p.parts = partition(mesh, p.graph, p.labels.label, p.face_part, options.partition, &voted_confidence);
  // Fragment merging may have changed labels: confidence is the new label's vote share.
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const float total = p.votes.total[static_cast<std::size_t>(f)];
    const int l = p.labels.label[static_cast<std::size_t>(f)];
    const float* h = p.votes.of(f);
    p.labels.confidence[static_cast<std::size_t>(f)] = h != nullptr && total > 0.f && l >= 0 ? h[l] / total : 0.f;
  }
  return p;
}

LabelMap render_face_labels(const View& view, const std::vector<int>& face_labels) {
  LabelMap out;
  out.labels.reset(view.face_id.width(), view.face_id.height(), 1, kUnknownLabel);
  for (std::size_t i = 0; i < view.face_id.size(); ++i) {
    const int f = view.face_id.data()[i];
    if (f >= 0 && static_cast<std::size_t>(f) < face_labels.size()) out.labels.data()[i] = face_labels[f];
  }
  return out;
}

}  // namespace g2p
