// Per-face voting over all views (the paper's Eq. 1, and a soft variant).
#include <cmath>

#include "g2p/project.h"

namespace g2p {

Result<FaceVotes> vote(const Mesh& mesh, const std::vector<View>& views, const std::vector<LabelMap>& maps,
                       int num_classes, const VoteOptions& options) {
  if (views.size() != maps.size())
    return Status::InvalidArgument("vote: " + std::to_string(views.size()) + " views but " +
                                   std::to_string(maps.size()) + " label maps");
  if (num_classes <= 0) return Status::InvalidArgument("vote: num_classes must be > 0");
  const int nf = mesh.num_faces();
  FaceVotes votes;
  votes.num_classes = num_classes;
  votes.total.assign(static_cast<std::size_t>(nf), 0.f);
  votes.row.assign(static_cast<std::size_t>(nf), -1);

  std::vector<Eigen::Vector3f> normals;
  if (options.weight_by_angle || options.weight_by_footprint) {
    normals.resize(static_cast<std::size_t>(nf));
    for (int f = 0; f < nf; ++f) normals[static_cast<std::size_t>(f)] = face_normal(mesh, f).cast<float>();
  }
  // First pass: checks, and a histogram row for every face some pixel sees.
  int rows = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const View& view = views[v];
    const LabelMap& map = maps[v];
    const std::string where = "vote: view " + std::to_string(v);
    if (map.labels.width() != view.face_id.width() || map.labels.height() != view.face_id.height())
      return Status::InvalidArgument(where + ": label map and face-ID buffer differ in size");
    for (std::size_t i = 0; i < view.face_id.size(); ++i) {
      const int f = view.face_id.data()[i];
      if (f < 0) continue;
      if (f >= nf) return Status::InvalidArgument(where + ": face ID " + std::to_string(f) + " out of range");
      int& r = votes.row[static_cast<std::size_t>(f)];
      if (r < 0) r = rows++;
    }
  }
  votes.histogram.assign(static_cast<std::size_t>(rows) * num_classes, 0.f);

  for (std::size_t v = 0; v < views.size(); ++v) {
    const View& view = views[v];
    const LabelMap& map = maps[v];
    const int w = view.face_id.width(), h = view.face_id.height();
    const std::string where = "vote: view " + std::to_string(v);
    const bool soft = options.mode == VoteMode::kSoft;
    if (soft && (map.probabilities.width() != w || map.probabilities.height() != h ||
                 map.probabilities.channels() != num_classes))
      return Status::InvalidArgument(where + ": soft votes need probabilities with " + std::to_string(num_classes) +
                                     " classes");
    if (options.weight_by_footprint && (view.depth.width() != w || view.depth.height() != h))
      return Status::InvalidArgument(where + ": footprint weights need the depth buffer");
    const Camera& cam = view.camera;
    const Eigen::Matrix3f rotation = cam.rotation.cast<float>();
    const float inv_fx = static_cast<float>(1.0 / cam.fx), inv_fy = static_cast<float>(1.0 / cam.fy);
    const float pixel_area = inv_fx * inv_fy;  // at depth 1 (perspective) or in m^2 (orthographic)

    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int f = view.face_id.at(x, y);
        if (f < 0) continue;
        const int label = map.labels.at(x, y);
        if (!soft && (label < 0 || label >= num_classes)) continue;
        float weight = 1.f;
        if (!normals.empty()) {
          const Eigen::Vector3f ray =
              cam.orthographic ? rotation.col(2)
                               : (rotation * Eigen::Vector3f((x + 0.5f - static_cast<float>(cam.cx)) * inv_fx,
                                                             (y + 0.5f - static_cast<float>(cam.cy)) * inv_fy, 1.f))
                                     .normalized();
          const float cosine = std::max(std::abs(normals[static_cast<std::size_t>(f)].dot(ray)), 1e-3f);
          if (options.weight_by_angle) weight *= cosine;
          if (options.weight_by_footprint) {
            // The surface a pixel covers: its area at that depth over the cosine.
            const float z = cam.orthographic ? 1.f : view.depth.at(x, y);
            weight *= pixel_area * z * z / cosine;
          }
        }
        float* hist =
            votes.histogram.data() + static_cast<std::size_t>(votes.row[static_cast<std::size_t>(f)]) * num_classes;
        if (soft) {
          const float* p = map.probabilities.pixel(x, y);
          float sum = 0.f;
          for (int c = 0; c < num_classes; ++c) hist[c] += weight * p[c], sum += p[c];
          votes.total[static_cast<std::size_t>(f)] += weight * sum;
        } else {
          hist[label] += weight;
          votes.total[static_cast<std::size_t>(f)] += weight;
        }
      }
    }
  }
  return votes;
}

}  // namespace g2p
