// eval: accuracy of mass estimates (below) and of material segmentation, as the paper measures it (after
// Cityscapes and MMSegmentation): one confusion matrix aggregated over a whole
// set, IoU per class = TP / (TP + FP + FN), mIoU = the unweighted mean over
// the classes present in the ground truth. Void (kUnknownLabel) ground truth
// is left out; an unknown prediction on a labelled pixel counts against the
// true class (a false negative) and for no other.
#pragma once

#include <string>
#include <vector>

#include "g2p/image.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

class G2P_API ConfusionMatrix {
 public:
  explicit ConfusionMatrix(int num_classes = 0);

  int num_classes() const { return num_classes_; }

  // One sample (a pixel, or a face weighted by its area). Labels outside
  // [0, num_classes) other than kUnknownLabel are ignored.
  void add(int truth, int predicted, double weight = 1.0);
  // Every pixel of two label images of one size (InvalidArgument otherwise).
  Status add(const ImageI32& truth, const ImageI32& predicted);
  // Every face, weighted by its area in m^2.
  Status add_faces(const Mesh& mesh, const std::vector<int>& truth, const std::vector<int>& predicted);
  // Adds `other`'s counts, each times `weight`: merge(m, 1 / m.total()) makes
  // every merged matrix count the same (models in different units, say).
  void merge(const ConfusionMatrix& other, double weight = 1.0);

  // Weight with ground truth `truth` predicted as `predicted` (kUnknownLabel allowed).
  double count(int truth, int predicted) const;
  bool present(int c) const;  // the class occurs in the ground truth
  double iou(int c) const;    // NaN when the class is neither true nor predicted anywhere
  double mean_iou() const;    // over present classes; NaN when none
  double accuracy() const;    // correct weight / labelled weight
  double total() const;       // labelled (non-void) weight

  // A table like the paper's Table 2: IoU % per class present, then mIoU.
  std::string table(const MaterialTable& table) const;
  // {"classes": [...], "iou": {...}, "miou": ..., "accuracy": ..., "matrix": [[...]]}.
  std::string to_json(const MaterialTable& table) const;

 private:
  int num_classes_;
  std::vector<double> counts_;  // num_classes x (num_classes + 1): the last column is "unknown"
};

// How far a set's mIoU could move with another draw of models: a percentile
// bootstrap (Efron & Tibshirani 1993, ch. 13) over models. Each resample draws
// as many models as there are, with replacement, merges their matrices with
// every model weighing the same (merge(m, 1 / m.total())) and takes the mIoU;
// the interval holds the central `confidence` share of the resampled values.
// A small test set of a few dozen models gives intervals several mIoU points
// wide: differences between segmenters inside them are not resolved.
struct MeanIouInterval {
  double miou = 0.0;  // of all models, each weighing the same
  double low = 0.0;   // lower and upper percentile of the resampled mIoU
  double high = 0.0;
  double confidence = 0.95;
  int resamples = 0;
};

// Fails when no matrix has a labelled sample, the matrices differ in their
// number of classes, `confidence` is outside (0, 1) or `resamples` < 10.
// Matrices with nothing labelled are left out. Deterministic for a given seed.
G2P_API Result<MeanIouInterval> bootstrap_mean_iou(const std::vector<ConfusionMatrix>& per_model,
                                                   double confidence = 0.95, int resamples = 2000, unsigned seed = 1);

// Whether segmenter B beats segmenter A on the same models: a paired
// percentile bootstrap of mIoU(B) - mIoU(A). Each resample draws models with
// replacement and scores both segmenters on that same draw (every model
// weighing the same, as above), so the spread that comes from which models
// were drawn (hard ones, easy ones) cancels in the difference: its interval is
// far narrower than the two separate intervals suggest, and a difference
// whose interval excludes zero is one the models resolve.
struct MeanIouDifference {
  double miou_a = 0.0;  // of all models, each weighing the same
  double miou_b = 0.0;
  double difference = 0.0;  // miou_b - miou_a
  double low = 0.0;         // lower and upper percentile of the resampled differences
  double high = 0.0;
  double confidence = 0.95;
  int resamples = 0;
  int models = 0;  // models with a labelled sample
};

// `a` and `b` hold the same models in the same order: model i's ground truth
// (its per-class row sums) must agree, within a relative 1e-6, or it fails
// naming the model. Otherwise fails as bootstrap_mean_iou does.
G2P_API Result<MeanIouDifference> bootstrap_mean_iou_difference(const std::vector<ConfusionMatrix>& a,
                                                                const std::vector<ConfusionMatrix>& b,
                                                                double confidence = 0.95, int resamples = 2000,
                                                                unsigned seed = 1);

// A matrix back from ConfusionMatrix::to_json's text (its "classes" and
// "matrix_rows_truth_columns_predicted_then_unknown"); `what` names the text
// in errors (a file and a key, say).
G2P_API Result<ConfusionMatrix> confusion_matrix_from_json(const std::string& text, const std::string& what);

// Calibration of predicted probabilities: how far the confidence of the top
// class is from the accuracy it achieves. Expected calibration error (Guo et
// al. 2017, "On Calibration of Modern Neural Networks"): samples are binned by
// confidence; ECE = sum over bins of (bin weight / total) x |accuracy - mean
// confidence|. 0 is perfect.
class G2P_API CalibrationBins {
 public:
  explicit CalibrationBins(int bins = 10);
  void add(float confidence, bool correct, double weight = 1.0);
  // Every labelled pixel (truth not void) of a label map with probabilities.
  Status add(const ImageI32& truth, const ImageI32& predicted, const ImageF& probabilities);
  void merge(const CalibrationBins& other);
  double expected_calibration_error() const;  // NaN when empty
  double mean_confidence() const;
  double accuracy() const;

 private:
  std::vector<double> weight_, confidence_, correct_;
};

// ---- Mass -------------------------------------------------------------------

// Mass errors as NeRF2Physics defines them (Zhai et al. 2024) and the
// Gen2Physics paper reports them (Table 1), each averaged over objects, with
// p the predicted and g the true mass: ADE = |p - g| (kg), ALDE = |ln p - ln g|,
// APE = |p - g| / g, MnRE = min(p / g, g / p) (higher is better).
struct MassErrors {
  int objects = 0;
  double ade_kg = 0.0;
  double alde = 0.0;
  double ape = 0.0;
  double mnre = 0.0;
};

// Fails unless both lists have the same non-zero length and every mass is
// positive and finite (the error names the index).
G2P_API Result<MassErrors> mass_errors(const std::vector<double>& predicted_kg, const std::vector<double>& true_kg);

}  // namespace g2p
