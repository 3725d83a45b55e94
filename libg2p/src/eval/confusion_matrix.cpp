// ConfusionMatrix: segmentation accuracy aggregated over a set.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/json_text.h"
#include "g2p/eval.h"

namespace g2p {

ConfusionMatrix::ConfusionMatrix(int num_classes)
    : num_classes_(std::max(0, num_classes)),
      counts_(static_cast<std::size_t>(num_classes_) * static_cast<std::size_t>(num_classes_ + 1), 0.0) {}

void ConfusionMatrix::add(int truth, int predicted, double weight) {
  if (truth < 0 || truth >= num_classes_ || !(weight > 0.0)) return;         // void ground truth
  if (predicted < 0 || predicted >= num_classes_) predicted = num_classes_;  // unknown
  counts_[static_cast<std::size_t>(truth) * (num_classes_ + 1) + predicted] += weight;
}

Status ConfusionMatrix::add(const ImageI32& truth, const ImageI32& predicted) {
  if (truth.width() != predicted.width() || truth.height() != predicted.height() || truth.channels() != 1 ||
      predicted.channels() != 1)
    return Status::InvalidArgument("confusion matrix: label images differ in size (" + std::to_string(truth.width()) +
                                   "x" + std::to_string(truth.height()) + " vs " + std::to_string(predicted.width()) +
                                   "x" + std::to_string(predicted.height()) + ")");
  for (std::size_t i = 0; i < truth.size(); ++i) add(truth.data()[i], predicted.data()[i]);
  return Status::Ok();
}

Status ConfusionMatrix::add_faces(const Mesh& mesh, const std::vector<int>& truth, const std::vector<int>& predicted) {
  const std::size_t n = mesh.triangles.size();
  if (truth.size() != n || predicted.size() != n)
    return Status::InvalidArgument("confusion matrix: " + std::to_string(truth.size()) + " true and " +
                                   std::to_string(predicted.size()) + " predicted face labels for " +
                                   std::to_string(n) + " faces");
  for (std::size_t f = 0; f < n; ++f) add(truth[f], predicted[f], face_area(mesh, static_cast<int>(f)));
  return Status::Ok();
}

void ConfusionMatrix::merge(const ConfusionMatrix& other, double weight) {
  if (other.num_classes_ != num_classes_ || !std::isfinite(weight)) return;
  for (std::size_t i = 0; i < counts_.size(); ++i) counts_[i] += weight * other.counts_[i];
}

double ConfusionMatrix::count(int truth, int predicted) const {
  if (truth < 0 || truth >= num_classes_) return 0.0;
  if (predicted < 0 || predicted >= num_classes_) predicted = num_classes_;
  return counts_[static_cast<std::size_t>(truth) * (num_classes_ + 1) + predicted];
}

bool ConfusionMatrix::present(int c) const {
  double row = 0.0;
  for (int p = 0; p <= num_classes_; ++p) row += count(c, p == num_classes_ ? kUnknownLabel : p);
  return row > 0.0;
}

double ConfusionMatrix::iou(int c) const {
  if (c < 0 || c >= num_classes_) return std::numeric_limits<double>::quiet_NaN();
  const double tp = count(c, c);
  double fn = 0.0, fp = 0.0;
  for (int p = 0; p <= num_classes_; ++p)
    if (p != c) fn += count(c, p == num_classes_ ? kUnknownLabel : p);
  for (int t = 0; t < num_classes_; ++t)
    if (t != c) fp += count(t, c);
  const double denominator = tp + fp + fn;
  return denominator > 0.0 ? tp / denominator : std::numeric_limits<double>::quiet_NaN();
}

double ConfusionMatrix::mean_iou() const {
  double sum = 0.0;
  int n = 0;
  for (int c = 0; c < num_classes_; ++c) {
    if (!present(c)) continue;
    sum += iou(c);
    ++n;
  }
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

double ConfusionMatrix::total() const {
  double t = 0.0;
  for (double v : counts_) t += v;
  return t;
}

double ConfusionMatrix::accuracy() const {
  double correct = 0.0;
  for (int c = 0; c < num_classes_; ++c) correct += count(c, c);
  const double t = total();
  return t > 0.0 ? correct / t : std::numeric_limits<double>::quiet_NaN();
}

std::string ConfusionMatrix::table(const MaterialTable& table) const {
  std::ostringstream header, values;
  header << "|";
  values << "|";
  for (int c = 0; c < num_classes_; ++c) {
    if (!present(c)) continue;
    const std::string name = table.valid_label(c) ? table[c].name : "class " + std::to_string(c);
    char cell[32];
    std::snprintf(cell, sizeof(cell), " %6.2f |", 100.0 * iou(c));
    header << " " << name << " |";
    values << cell;
  }
  char miou[32];
  std::snprintf(miou, sizeof(miou), " %6.2f |", 100.0 * mean_iou());
  header << " mIoU |";
  values << miou;
  std::ostringstream out;
  out << header.str() << "\n";
  for (int c = 0; c <= num_classes_; ++c)
    if (c == num_classes_ || present(c)) out << "|---";
  out << "|\n" << values.str() << "\n";
  return out.str();
}

std::string ConfusionMatrix::to_json(const MaterialTable& table) const {
  using nlohmann::json;
  json classes = json::array(), iou_json = json::object(), matrix = json::array();
  for (int c = 0; c < num_classes_; ++c) {
    const std::string name = table.valid_label(c) ? table[c].name : "class " + std::to_string(c);
    classes.push_back(name);
    if (present(c)) iou_json[name] = iou(c);
    json row = json::array();
    for (int p = 0; p <= num_classes_; ++p) row.push_back(count(c, p == num_classes_ ? kUnknownLabel : p));
    matrix.push_back(row);
  }
  const double m = mean_iou(), a = accuracy();
  json doc = {{"classes", classes},
              {"iou", iou_json},
              {"miou", std::isnan(m) ? json(nullptr) : json(m)},
              {"accuracy", std::isnan(a) ? json(nullptr) : json(a)},
              {"total_weight", total()},
              {"matrix_rows_truth_columns_predicted_then_unknown", matrix}};
  return detail::json_text(doc, 2) + "\n";
}

}  // namespace g2p

namespace g2p {

CalibrationBins::CalibrationBins(int bins)
    : weight_(static_cast<std::size_t>(std::max(1, bins)), 0.0),
      confidence_(weight_.size(), 0.0),
      correct_(weight_.size(), 0.0) {}

void CalibrationBins::add(float confidence, bool correct, double weight) {
  if (!(weight > 0.0) || !std::isfinite(confidence)) return;
  const float c = std::clamp(confidence, 0.f, 1.f);
  const std::size_t bin = std::min(weight_.size() - 1, static_cast<std::size_t>(c * weight_.size()));
  weight_[bin] += weight;
  confidence_[bin] += weight * c;
  correct_[bin] += correct ? weight : 0.0;
}

Status CalibrationBins::add(const ImageI32& truth, const ImageI32& predicted, const ImageF& probabilities) {
  if (truth.width() != predicted.width() || truth.height() != predicted.height() ||
      probabilities.width() != truth.width() || probabilities.height() != truth.height())
    return Status::InvalidArgument("calibration: label images and probabilities differ in size");
  for (int y = 0; y < truth.height(); ++y) {
    for (int x = 0; x < truth.width(); ++x) {
      const int t = truth.at(x, y), p = predicted.at(x, y);
      if (t < 0) continue;
      const float confidence = p >= 0 && p < probabilities.channels() ? probabilities.at(x, y, p) : 0.f;
      add(confidence, t == p);
    }
  }
  return Status::Ok();
}

void CalibrationBins::merge(const CalibrationBins& other) {
  if (other.weight_.size() != weight_.size()) return;
  for (std::size_t b = 0; b < weight_.size(); ++b) {
    weight_[b] += other.weight_[b];
    confidence_[b] += other.confidence_[b];
    correct_[b] += other.correct_[b];
  }
}

double CalibrationBins::expected_calibration_error() const {
  double total = 0.0, ece = 0.0;
  for (double w : weight_) total += w;
  if (!(total > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  for (std::size_t b = 0; b < weight_.size(); ++b)
    if (weight_[b] > 0.0) ece += std::abs(correct_[b] - confidence_[b]) / total;
  return ece;
}

double CalibrationBins::mean_confidence() const {
  double total = 0.0, c = 0.0;
  for (std::size_t b = 0; b < weight_.size(); ++b) total += weight_[b], c += confidence_[b];
  return total > 0.0 ? c / total : std::numeric_limits<double>::quiet_NaN();
}

double CalibrationBins::accuracy() const {
  double total = 0.0, c = 0.0;
  for (std::size_t b = 0; b < weight_.size(); ++b) total += weight_[b], c += correct_[b];
  return total > 0.0 ? c / total : std::numeric_limits<double>::quiet_NaN();
}

Result<ConfusionMatrix> confusion_matrix_from_json(const std::string& text, const std::string& what) {
  using nlohmann::json;
  const json doc = json::parse(text, nullptr, false);
  const char* key = "matrix_rows_truth_columns_predicted_then_unknown";
  if (doc.is_discarded() || !doc.is_object() || !doc.contains(key) || !doc[key].is_array())
    return Status::InvalidArgument(what + ": expected a confusion matrix ({\"" + key + "\": [[...]], ...})");
  const json& rows = doc[key];
  const int n = static_cast<int>(rows.size());
  if (doc.contains("classes") && (!doc["classes"].is_array() || static_cast<int>(doc["classes"].size()) != n))
    return Status::InvalidArgument(what + ": \"classes\" does not list one class per matrix row (" + std::to_string(n) +
                                   " rows)");
  ConfusionMatrix m(n);
  for (int t = 0; t < n; ++t) {
    const json& row = rows[static_cast<std::size_t>(t)];
    if (!row.is_array() || static_cast<int>(row.size()) != n + 1)
      return Status::InvalidArgument(what + ": row " + std::to_string(t) + " must hold " + std::to_string(n + 1) +
                                     " numbers (the predicted classes, then unknown)");
    for (int p = 0; p <= n; ++p) {
      const json& cell = row[static_cast<std::size_t>(p)];
      if (!cell.is_number() || !(cell.get<double>() >= 0.0) || !std::isfinite(cell.get<double>()))
        return Status::InvalidArgument(what + ": row " + std::to_string(t) + ", column " + std::to_string(p) +
                                       ": expected a finite count >= 0");
      if (cell.get<double>() > 0.0) m.add(t, p == n ? kUnknownLabel : p, cell.get<double>());
    }
  }
  return m;
}

}  // namespace g2p
