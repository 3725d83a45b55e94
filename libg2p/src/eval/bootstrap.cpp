// Percentile bootstrap of the per-model mIoU (eval.h).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "g2p/eval.h"

namespace g2p {

Result<MeanIouInterval> bootstrap_mean_iou(const std::vector<ConfusionMatrix>& per_model, double confidence,
                                           int resamples, unsigned seed) {
  if (!(confidence > 0.0 && confidence < 1.0))
    return Status::InvalidArgument("bootstrap_mean_iou: confidence must be in (0, 1), got " +
                                   std::to_string(confidence));
  if (resamples < 10)
    return Status::InvalidArgument("bootstrap_mean_iou: needs at least 10 resamples, got " + std::to_string(resamples));
  std::vector<const ConfusionMatrix*> models;
  for (std::size_t i = 0; i < per_model.size(); ++i) {
    if (per_model[i].num_classes() != per_model.front().num_classes())
      return Status::InvalidArgument("bootstrap_mean_iou: matrix " + std::to_string(i) + " has " +
                                     std::to_string(per_model[i].num_classes()) + " classes, matrix 0 has " +
                                     std::to_string(per_model.front().num_classes()));
    if (per_model[i].total() > 0) models.push_back(&per_model[i]);
  }
  if (models.empty()) return Status::InvalidArgument("bootstrap_mean_iou: no matrix has a labelled sample");

  const int classes = models.front()->num_classes();
  const auto merged_miou = [&](const auto& pick) {
    ConfusionMatrix sum(classes);
    for (std::size_t i = 0; i < models.size(); ++i) sum.merge(*models[pick(i)], 1.0 / models[pick(i)]->total());
    return sum.mean_iou();
  };
  MeanIouInterval out;
  out.confidence = confidence;
  out.resamples = resamples;
  out.miou = merged_miou([](std::size_t i) { return i; });

  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> draw(0, models.size() - 1);
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(resamples));
  std::vector<std::size_t> picks(models.size());
  for (int r = 0; r < resamples; ++r) {
    for (std::size_t& p : picks) p = draw(rng);
    const double v = merged_miou([&](std::size_t i) { return picks[i]; });
    if (v == v) values.push_back(v);  // a resample without any present class has no mIoU
  }
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double at = q * static_cast<double>(values.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(at));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  out.low = quantile(0.5 * (1.0 - confidence));
  out.high = quantile(0.5 * (1.0 + confidence));
  return out;
}

}  // namespace g2p
