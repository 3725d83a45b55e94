// compare: two segmentation runs (`g2p eval seg --json` documents) on the
// same models, the paired bootstrap of their per-face mIoU difference
// (`g2p eval compare`).
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "core/json_text.h"
#include "g2p/eval.h"

namespace g2p {

namespace {

using nlohmann::json;

// One run: its settings and per-model 3D matrices.
struct ScoredRun {
  std::string name;
  json doc;
  std::vector<std::string> keys;
  std::vector<ConfusionMatrix> matrices;
  std::vector<std::string> classes;  // the first model's "3d" "classes"; "" where not a string
};

Result<ScoredRun> parse_run(const std::string& text, const std::string& name) {
  ScoredRun out;
  out.name = name;
  out.doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (out.doc.is_discarded() || !out.doc.is_object() || !out.doc.contains("models") || !out.doc["models"].is_object())
    return Status::InvalidArgument(name + ": not a g2p eval seg --json file (no \"models\" object)");
  for (const auto& item : out.doc["models"].items()) {
    if (!item.value().is_object() || !item.value().contains("3d"))
      return Status::InvalidArgument(name + ": model " + item.key() + " has no \"3d\" matrix");
    const json& faces = item.value()["3d"];
    Result<ConfusionMatrix> m = confusion_matrix_from_json(faces.dump(), name + ": " + item.key());
    if (!m.ok()) return m.status();
    if (out.classes.empty() && faces.contains("classes") && faces["classes"].is_array())
      for (const json& c : faces["classes"]) out.classes.push_back(c.is_string() ? c.get<std::string>() : "");
    out.keys.push_back(item.key());
    out.matrices.push_back(std::move(*m));
  }
  if (out.keys.empty()) return Status::InvalidArgument(name + ": scores no model");
  return out;
}

Result<ScoredRun> read_run(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_run(text.str(), path);
}

// A string setting of the document, or `fallback` where it is absent or not a string.
std::string text_setting(const json& doc, const char* key, const std::string& fallback) {
  const auto at = doc.find(key);
  return at != doc.end() && at->is_string() ? at->get<std::string>() : fallback;
}

std::string run_label(const json& doc) {
  std::string s = text_setting(doc, "segmenter", "?");
  const std::string refiner = text_setting(doc, "refiner", "");
  if (!refiner.empty() && refiner != "none") s += " + " + refiner;
  return s + ", " + text_setting(doc, "vote", "?") + " votes";
}

// What the two runs were scored with, where it differs (not the segmenter: that is what is compared).
std::string differing_conditions(const json& a, const json& b) {
  std::string out;
  for (const char* key : {"anonymized_names", "base_color_only", "vote", "views", "resolution"}) {
    const json va = a.value(key, json()), vb = b.value(key, json());
    if (va != vb)
      out += std::string(out.empty() ? "" : ", ") + key + " (" + detail::json_text(va) + " / " + detail::json_text(vb) +
             ")";
  }
  return out;
}

Result<SegmentationComparison> compare_runs(const ScoredRun& a, const ScoredRun& b,
                                            const SegmentationComparisonOptions& options) {
  // The same models on both sides, in A's order.
  std::vector<ConfusionMatrix> right;
  std::vector<std::string> only_a;
  for (const std::string& key : a.keys) {
    const auto at = std::find(b.keys.begin(), b.keys.end(), key);
    if (at == b.keys.end())
      only_a.push_back(key);
    else
      right.push_back(b.matrices[static_cast<std::size_t>(at - b.keys.begin())]);
  }
  if (!only_a.empty() || a.keys.size() != b.keys.size())
    return Status::InvalidArgument(
        a.name + " and " + b.name + " score other models (" + std::to_string(a.keys.size()) + " and " +
        std::to_string(b.keys.size()) + " models" +
        (only_a.empty() ? ""
                        : "; only in the first: " + only_a.front() +
                              (only_a.size() > 1 ? " and " + std::to_string(only_a.size() - 1) + " more" : "")) +
        "); a paired comparison needs the same models");
  Result<MeanIouDifference> d =
      bootstrap_mean_iou_difference(a.matrices, right, options.confidence, options.resamples, options.seed);
  if (!d.ok()) return d.status();

  SegmentationComparison out;
  out.a = a.name;
  out.b = b.name;
  out.label_a = run_label(a.doc);
  out.label_b = run_label(b.doc);
  out.differing_conditions = differing_conditions(a.doc, b.doc);
  out.difference = *d;
  // Per class, every model weighing the same.
  const int classes = a.matrices.front().num_classes();
  ConfusionMatrix sum_a(classes), sum_b(classes);
  for (std::size_t i = 0; i < right.size(); ++i) {
    if (a.matrices[i].total() <= 0) continue;
    sum_a.merge(a.matrices[i], 1.0 / a.matrices[i].total());
    sum_b.merge(right[i], 1.0 / right[i].total());
  }
  for (int c = 0; c < classes; ++c) {
    if (!sum_a.present(c)) continue;
    const auto i = static_cast<std::size_t>(c);
    out.per_class.push_back(
        {i < a.classes.size() && !a.classes[i].empty() ? a.classes[i] : "class " + std::to_string(c), sum_a.iou(c),
         sum_b.iou(c)});
  }
  return out;
}

// printf into a string.
std::string format(const char* fmt, ...) {
  va_list args, copy;
  va_start(args, fmt);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
  va_end(args);
  return out;
}

}  // namespace

std::string SegmentationComparison::to_text() const {
  const MeanIouDifference& d = difference;
  std::string out = format("A: %s (%s): mIoU %.2f %%\n", a.c_str(), label_a.c_str(), 100.0 * d.miou_a);
  out += format("B: %s (%s): mIoU %.2f %%\n", b.c_str(), label_b.c_str(), 100.0 * d.miou_b);
  out += format("B - A: %+.2f points, %.0f %% interval %+.2f to %+.2f (paired bootstrap, %d resamples of %d models)\n",
                100.0 * d.difference, 100.0 * d.confidence, 100.0 * d.low, 100.0 * d.high, d.resamples, d.models);
  out += d.low > 0.0    ? "B is better: the interval lies above zero\n"
         : d.high < 0.0 ? "B is worse: the interval lies below zero\n"
                        : "not resolved: the interval includes zero\n";
  out += "\nPer face (3D), each model weighing the same, IoU %:\n| class | A | B | B - A |\n|---|---:|---:|---:|\n";
  for (const ClassIou& c : per_class)
    out += format("| %s | %.1f | %.1f | %+.1f |\n", c.name.c_str(), 100.0 * c.a, 100.0 * c.b, 100.0 * (c.b - c.a));
  return out;
}

std::string SegmentationComparison::to_json() const {
  json per_class_json = json::object();
  for (const ClassIou& c : per_class) per_class_json[c.name] = {{"a", c.a}, {"b", c.b}};
  const json j = {{"a", a},
                  {"b", b},
                  {"miou_a", difference.miou_a},
                  {"miou_b", difference.miou_b},
                  {"difference", difference.difference},
                  {"low", difference.low},
                  {"high", difference.high},
                  {"confidence", difference.confidence},
                  {"resamples", difference.resamples},
                  {"models", difference.models},
                  {"iou_per_class", per_class_json}};
  return detail::json_text(j, 2);
}

Result<SegmentationComparison> compare_segmentation_runs(const std::string& json_a, const std::string& name_a,
                                                         const std::string& json_b, const std::string& name_b,
                                                         const SegmentationComparisonOptions& options) {
  Result<ScoredRun> a = parse_run(json_a, name_a);
  if (!a.ok()) return a.status();
  Result<ScoredRun> b = parse_run(json_b, name_b);
  if (!b.ok()) return b.status();
  return compare_runs(*a, *b, options);
}

Result<SegmentationComparison> compare_segmentation_files(const std::string& path_a, const std::string& path_b,
                                                          const SegmentationComparisonOptions& options) {
  // A is read and checked before B is opened.
  Result<ScoredRun> a = read_run(path_a);
  if (!a.ok()) return a.status();
  Result<ScoredRun> b = read_run(path_b);
  if (!b.ok()) return b.status();
  return compare_runs(*a, *b, options);
}

}  // namespace g2p
