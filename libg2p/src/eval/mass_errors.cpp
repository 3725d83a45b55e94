// mass_errors: NeRF2Physics' mass metrics.
#include <algorithm>
#include <cmath>

#include "g2p/eval.h"

namespace g2p {

Result<MassErrors> mass_errors(const std::vector<double>& predicted_kg, const std::vector<double>& true_kg) {
  if (predicted_kg.size() != true_kg.size())
    return Status::InvalidArgument("mass_errors: " + std::to_string(predicted_kg.size()) + " predictions for " +
                                   std::to_string(true_kg.size()) + " true masses");
  if (predicted_kg.empty()) return Status::InvalidArgument("mass_errors: no objects");
  MassErrors e;
  for (std::size_t i = 0; i < predicted_kg.size(); ++i) {
    const double p = predicted_kg[i], g = true_kg[i];
    if (!(p > 0 && std::isfinite(p)) || !(g > 0 && std::isfinite(g)))
      return Status::InvalidArgument("mass_errors: object " + std::to_string(i) +
                                     " needs positive finite masses (predicted " + std::to_string(p) + ", true " +
                                     std::to_string(g) + ")");
    e.ade_kg += std::abs(p - g);
    e.alde += std::abs(std::log(p) - std::log(g));
    e.ape += std::abs(p - g) / g;
    e.mnre += std::min(p / g, g / p);
  }
  e.objects = static_cast<int>(predicted_kg.size());
  e.ade_kg /= e.objects;
  e.alde /= e.objects;
  e.ape /= e.objects;
  e.mnre /= e.objects;
  return e;
}

}  // namespace g2p
