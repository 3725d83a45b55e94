// Percentile bootstraps of the per-model mIoU and of the paired difference of
// two segmenters' mIoU (eval.h).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "g2p/eval.h"

namespace g2p {
namespace {

Status check_settings(const char* what, double confidence, int resamples) {
  if (!(confidence > 0.0 && confidence < 1.0))
    return Status::InvalidArgument(std::string(what) + ": confidence must be in (0, 1), got " +
                                   std::to_string(confidence));
  if (resamples < 10)
    return Status::InvalidArgument(std::string(what) + ": needs at least 10 resamples, got " +
                                   std::to_string(resamples));
  return Status::Ok();
}

Status check_classes(const char* what, const std::vector<ConfusionMatrix>& per_model, int classes) {
  for (std::size_t i = 0; i < per_model.size(); ++i)
    if (per_model[i].num_classes() != classes)
      return Status::InvalidArgument(std::string(what) + ": matrix " + std::to_string(i) + " has " +
                                     std::to_string(per_model[i].num_classes()) + " classes, matrix 0 has " +
                                     std::to_string(classes));
  return Status::Ok();
}

// The mIoU of the models `pick(0) .. pick(n - 1)` of `models`, each weighing the same.
template <typename Pick>
double merged_miou(const std::vector<const ConfusionMatrix*>& models, const Pick& pick) {
  ConfusionMatrix sum(models.front()->num_classes());
  for (std::size_t i = 0; i < models.size(); ++i) sum.merge(*models[pick(i)], 1.0 / models[pick(i)]->total());
  return sum.mean_iou();
}

// `resamples` draws of models.size() indices with replacement; `statistic`
// of each draw (NaN values, from draws without a present class, are left
// out); returns the `confidence` percentile interval of the values.
template <typename Statistic>
std::pair<double, double> percentile_interval(std::size_t models, double confidence, int resamples, unsigned seed,
                                              const Statistic& statistic) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> draw(0, models - 1);
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(resamples));
  std::vector<std::size_t> picks(models);
  for (int r = 0; r < resamples; ++r) {
    for (std::size_t& p : picks) p = draw(rng);
    const double v = statistic([&](std::size_t i) { return picks[i]; });
    if (v == v) values.push_back(v);
  }
  if (values.empty()) return {std::nan(""), std::nan("")};
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double at = q * static_cast<double>(values.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(at));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  return {quantile(0.5 * (1.0 - confidence)), quantile(0.5 * (1.0 + confidence))};
}

// Per class, the weight whose ground truth is that class.
std::vector<double> truth_totals(const ConfusionMatrix& m) {
  std::vector<double> out(static_cast<std::size_t>(m.num_classes()), 0.0);
  for (int t = 0; t < m.num_classes(); ++t) {
    for (int p = 0; p < m.num_classes(); ++p) out[static_cast<std::size_t>(t)] += m.count(t, p);
    out[static_cast<std::size_t>(t)] += m.count(t, kUnknownLabel);
  }
  return out;
}

}  // namespace

Result<MeanIouInterval> bootstrap_mean_iou(const std::vector<ConfusionMatrix>& per_model, double confidence,
                                           int resamples, unsigned seed) {
  if (Status s = check_settings("bootstrap_mean_iou", confidence, resamples); !s.ok()) return s;
  if (per_model.empty()) return Status::InvalidArgument("bootstrap_mean_iou: no matrix has a labelled sample");
  if (Status s = check_classes("bootstrap_mean_iou", per_model, per_model.front().num_classes()); !s.ok()) return s;
  std::vector<const ConfusionMatrix*> models;
  for (const ConfusionMatrix& m : per_model)
    if (m.total() > 0) models.push_back(&m);
  if (models.empty()) return Status::InvalidArgument("bootstrap_mean_iou: no matrix has a labelled sample");

  MeanIouInterval out;
  out.confidence = confidence;
  out.resamples = resamples;
  out.miou = merged_miou(models, [](std::size_t i) { return i; });
  std::tie(out.low, out.high) = percentile_interval(models.size(), confidence, resamples, seed,
                                                    [&](const auto& pick) { return merged_miou(models, pick); });
  return out;
}

Result<MeanIouDifference> bootstrap_mean_iou_difference(const std::vector<ConfusionMatrix>& a,
                                                        const std::vector<ConfusionMatrix>& b, double confidence,
                                                        int resamples, unsigned seed) {
  const char* what = "bootstrap_mean_iou_difference";
  if (Status s = check_settings(what, confidence, resamples); !s.ok()) return s;
  if (a.size() != b.size())
    return Status::InvalidArgument(std::string(what) + ": " + std::to_string(a.size()) + " models against " +
                                   std::to_string(b.size()) + "; both sides must hold the same models");
  if (a.empty()) return Status::InvalidArgument(std::string(what) + ": no matrix has a labelled sample");
  const int classes = a.front().num_classes();
  if (Status s = check_classes(what, a, classes); !s.ok()) return s;
  if (Status s = check_classes(what, b, classes); !s.ok()) return s;
  std::vector<const ConfusionMatrix*> left, right;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::vector<double> ta = truth_totals(a[i]), tb = truth_totals(b[i]);
    for (int c = 0; c < classes; ++c) {
      const double x = ta[static_cast<std::size_t>(c)], y = tb[static_cast<std::size_t>(c)];
      if (std::abs(x - y) > 1e-6 * std::max({std::abs(x), std::abs(y), 1e-300}))
        return Status::InvalidArgument(std::string(what) + ": model " + std::to_string(i) +
                                       " has other ground truth on the two sides (class " + std::to_string(c) + ": " +
                                       std::to_string(x) + " against " + std::to_string(y) +
                                       "); both must score the same models with the same labels");
    }
    if (a[i].total() > 0) {
      left.push_back(&a[i]);
      right.push_back(&b[i]);
    }
  }
  if (left.empty()) return Status::InvalidArgument(std::string(what) + ": no matrix has a labelled sample");

  MeanIouDifference out;
  out.confidence = confidence;
  out.resamples = resamples;
  out.models = static_cast<int>(left.size());
  const auto identity = [](std::size_t i) { return i; };
  out.miou_a = merged_miou(left, identity);
  out.miou_b = merged_miou(right, identity);
  out.difference = out.miou_b - out.miou_a;
  std::tie(out.low, out.high) = percentile_interval(left.size(), confidence, resamples, seed, [&](const auto& pick) {
    return merged_miou(right, pick) - merged_miou(left, pick);
  });
  return out;
}

}  // namespace g2p
