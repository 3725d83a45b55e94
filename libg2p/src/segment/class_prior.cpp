// apply_class_prior: a prior over classes on the pixels the image decided.
#include <cmath>

#include "g2p/segment.h"

namespace g2p {

Result<std::size_t> apply_class_prior(const std::vector<float>& weight, const std::vector<std::uint8_t>& image_decided,
                                      const View& view, LabelMap& map) {
  if (weight.empty() || map.probabilities.empty()) return std::size_t{0};
  const int k = map.probabilities.channels();
  if (static_cast<int>(weight.size()) != k)
    return Status::InvalidArgument("class prior: " + std::to_string(weight.size()) + " weights for " +
                                   std::to_string(k) + " classes");
  for (const float w : weight)
    if (!(w > 0.0f) || !std::isfinite(w))
      return Status::InvalidArgument("class prior: every weight must be positive and finite");
  if (view.face_id.width() != map.labels.width() || view.face_id.height() != map.labels.height() ||
      map.probabilities.width() != map.labels.width() || map.probabilities.height() != map.labels.height())
    return Status::InvalidArgument("class prior: the view and its label map differ in size");
  std::size_t changed = 0;
  for (int y = 0; y < view.face_id.height(); ++y)
    for (int x = 0; x < view.face_id.width(); ++x) {
      const int f = view.face_id.at(x, y);
      if (f < 0 || static_cast<std::size_t>(f) >= image_decided.size() ||
          image_decided[static_cast<std::size_t>(f)] == 0)
        continue;
      float* p = map.probabilities.pixel(x, y);
      double total = 0.0;
      for (int c = 0; c < k; ++c) total += static_cast<double>(p[c]) * weight[static_cast<std::size_t>(c)];
      if (!(total > 0.0)) continue;  // an unlabelled pixel
      int best = 0;
      for (int c = 0; c < k; ++c) {
        p[c] = static_cast<float>(p[c] * weight[static_cast<std::size_t>(c)] / total);
        if (p[c] > p[best]) best = c;
      }
      int& label = map.labels.at(x, y);
      if (label != kUnknownLabel && label != best) {
        label = best;
        ++changed;
      }
    }
  return changed;
}

}  // namespace g2p
