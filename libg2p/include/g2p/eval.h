// eval: accuracy of mass estimates (below) and of material segmentation, as the paper measures it (after
// Cityscapes and MMSegmentation): one confusion matrix aggregated over a whole
// set, IoU per class = TP / (TP + FP + FN), mIoU = the unweighted mean over
// the classes present in the ground truth. Void (kUnknownLabel) ground truth
// is left out; an unknown prediction on a labelled pixel counts against the
// true class (a false negative) and for no other.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "g2p/image.h"
#include "g2p/materials.h"
#include "g2p/mesh.h"
#include "g2p/pipeline.h"
#include "g2p/project.h"
#include "g2p/render.h"
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

// ---- Segmentation over a labelled set ------------------------------------------

// One model's scores.
struct SegmentationModelEval {
  std::string key;                  // its labels.json key
  ConfusionMatrix pixels;           // 2D: every labelled pixel of its views
  ConfusionMatrix faces;            // 3D: every labelled face, weighted by its area in m^2, after voting (refining)
  std::string kind = "unknown";     // the identified kind the run acted on, or "unknown"
  bool kind_prior_applied = false;  // its materials weighed the classes read from the image
  // The refine stage, when a refiner was chosen: its notes and the faces it
  // changed, or why it failed (the projected labels were scored then).
  bool refined = false;
  std::vector<std::string> refine_notes;
  std::size_t refine_changed_faces = 0;
  std::string refine_error;  // "" unless it failed
  // Warnings first met on this model: the segmenter's (a backend that
  // degraded; each said once per set) and a refiner's failure.
  std::vector<std::string> warnings;
};

// Scores a segmenter over a set of models with ground truth, as the paper's
// Table 2 does (`g2p eval seg`, g2p.evaluate_segmentation): each model runs
// through Pipeline from render to project (or refine, with a refiner), and
// its views are scored per pixel (2D) and its faces per area after voting
// (3D) against labels.json, read once per set. The truth of a pixel is the
// class of the source material of the face it sees, as the `oracle`
// segmenter gives it.
struct SegmentationEvalOptions {
  // Where the models are: each key of labels.json is a model file's path
  // relative to this folder (a generated dataset's labels.json), else the
  // shared assets' KEY/KEY.glb (--assets; relative to the working directory).
  std::string assets = "../shared/assets";
  // The ground truth, labels.json form ({"models": {KEY: {"labels": {"0":
  // "Wood", ...}, "split": ...}}}); "" = ASSETS/labels.json (--truth).
  std::string truth;
  std::vector<std::string> models;  // keys to score, in this order; empty = every key (--models)
  std::string split;                // only the keys whose entry has this "split"; "" = any (--split)
  MaterialTable materials = MaterialTable::paper_default();  // the classes scored (--materials)

  // What the segmenter sees: names removed (--anonymize-names) and every
  // material reduced to its base colour (--base-color-only), as image-to-3D
  // meshes come.
  bool anonymize_names = false;
  bool base_color_only = false;

  BackendChoice renderer = PipelineOptions{}.renderer;    // --renderer
  ViewOptions views;                                      // 11 views at 512 x 512 px (--views, --resolution, ...)
  BackendChoice segmenter = PipelineOptions{}.segmenter;  // the scored backend (--segmenter, --set KEY=VALUE)
  // Votes onto the faces: vote.mode kHard one vote per pixel, kSoft the
  // segmenter's probabilities (--soft).
  ProjectOptions project;
  // After voting: "none" scores the project stage alone (--refiner,
  // --refine-set KEY=VALUE; settings need a refiner other than none).
  BackendChoice refiner{"none", {}};

  // What the object is, as `g2p run` finds it ("none": not identified;
  // --identifier); a kind identified with at least `kind_confidence` weighs
  // the classes read from the image by its materials (`kind_prior`,
  // PipelineOptions::kind_prior). Its size is never assumed here.
  BackendChoice identifier{"none", {}};
  // The kind the model's own names give, read before anonymize_names removes
  // them, stands for a user's words (--object): needs an identifier that
  // reads them (auto or object) (--object-from-names).
  bool object_from_names = false;
  double kind_confidence = PipelineOptions{}.kind_confidence;  // [0, 1] (--kind-confidence)
  double kind_prior = PipelineOptions{}.kind_prior;            // (0, 1] (--kind-prior)

  // Also writes every region's features (regions.h) and true class to this
  // CSV, for training the region classifier (docs/regions.md); "" = none
  // (--region-features).
  std::string region_features;

  // Called after each model is scored, on the calling thread (a progress
  // line); null = none.
  std::function<void(const SegmentationModelEval&)> on_model;
};

struct G2P_API SegmentationEval {
  SegmentationEvalOptions options;            // what was scored, and how
  std::vector<SegmentationModelEval> models;  // in the order scored
  ConfusionMatrix total;                      // 2D: every pixel of every model
  ConfusionMatrix total_3d;                   // 3D: every face of every model by its area
  // 3D with each model's matrix scaled to a total of one, so that no model
  // weighs more for its size or units (the figure the paper's table gives).
  ConfusionMatrix total_3d_per_model;
  // bootstrap_mean_iou over the models' 3D matrices; empty when no model has
  // a labelled face.
  std::optional<MeanIouInterval> interval;
  CalibrationBins calibration;  // the segmenter's probabilities against the truth (empty without probabilities)

  // The `g2p eval seg --json` document: the settings, "total", "total_3d",
  // "total_3d_per_model" (ConfusionMatrix::to_json), their interval,
  // "calibration" and per model its "2d", "3d", "kind", "kind_prior_applied"
  // and "refine" (with a refiner); indented, without a final newline.
  std::string to_json() const;
  // What `g2p eval seg` prints after the models: the three IoU tables (per
  // pixel, per face by area, per face each model weighing the same), the mIoU
  // interval and the calibration, each line ending in a newline.
  std::string to_text() const;
};

// Runs one set evaluation: prepare() checks everything the options name
// before any model is read; run() scores the set.
class G2P_API SegmentationEvaluator {
 public:
  explicit SegmentationEvaluator(SegmentationEvalOptions options = {});
  ~SegmentationEvaluator();
  SegmentationEvaluator(SegmentationEvaluator&&) noexcept;
  SegmentationEvaluator& operator=(SegmentationEvaluator&&) noexcept;

  const SegmentationEvalOptions& options() const;

  // Creates every backend and checks the settings: a bad name, setting,
  // range or combination fails with kInvalidArgument or kNotFound naming the
  // option and its flag (a segmenter whose file is missing may fail with
  // another code). run() calls it.
  Status prepare();

  // Reads labels.json (once) and scores every model. Fails on the first
  // model that cannot be scored, naming its key; kCancelled once `context`
  // is cancelled (checked between stages and between models).
  Result<SegmentationEval> run(RunContext* context = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// SegmentationEvaluator(options).run(context).
G2P_API Result<SegmentationEval> evaluate_segmentation(const SegmentationEvalOptions& options,
                                                       RunContext* context = nullptr);

// ---- Two segmentation runs compared -------------------------------------------

// How compare_segmentation_runs pairs two runs (`g2p eval compare` flags).
struct SegmentationComparisonOptions {
  double confidence = 0.95;  // interval coverage, in (0, 1) (--confidence)
  int resamples = 2000;      // bootstrap resamples, at least 10 (--resamples)
  unsigned seed = 1;         // of the bootstrap: the same seed gives the same interval
};

// Is segmenter B better than segmenter A on the same models? Two
// SegmentationEval::to_json documents (`g2p eval seg --json` files) compared
// by bootstrap_mean_iou_difference over their per-model 3D matrices, every
// model weighing the same, as docs/training.md's shipping rule asks.
struct G2P_API SegmentationComparison {
  std::string a, b;              // what each run was read from (the file paths as given), A the reference
  std::string label_a, label_b;  // "SEGMENTER[ + REFINER], VOTE votes" from each document's settings
  // The settings the two were scored with that differ (names, base colour,
  // votes, views, resolution; not the segmenter: that is what is compared),
  // as `vote ("hard" / "soft"), views (3 / 6)`; "" when none.
  std::string differing_conditions;
  MeanIouDifference difference;  // B - A over the models both score, in A's order
  // IoU per face, every model weighing the same, of each class present in
  // A's ground truth (in class order; named by A's "classes", else "class N").
  struct ClassIou {
    std::string name;
    double a = 0.0;
    double b = 0.0;
  };
  std::vector<ClassIou> per_class;

  // What `g2p eval compare` prints: both mIoU, the difference with its
  // interval, the verdict (above zero, below it, or including it), then the
  // per-class table; ends with a newline.
  std::string to_text() const;
  // The `g2p eval compare --json` document: "a", "b", "miou_a", "miou_b",
  // "difference", "low", "high", "confidence", "resamples", "models" and
  // "iou_per_class" ({NAME: {"a": ..., "b": ...}}); indented, without a
  // final newline.
  std::string to_json() const;
};

// Compares two runs given as SegmentationEval::to_json text; `name_a` and
// `name_b` stand for them in errors and in the result (a path, say). Fails
// with kInvalidArgument naming the document when one is not such a document
// ("NAME: not a g2p eval seg --json file ..."), a model has no "3d" matrix or
// none is scored; when the two score other models (by key); when a model's
// ground truth differs between them; or as bootstrap_mean_iou_difference does.
G2P_API Result<SegmentationComparison> compare_segmentation_runs(const std::string& json_a, const std::string& name_a,
                                                                 const std::string& json_b, const std::string& name_b,
                                                                 const SegmentationComparisonOptions& options = {});
// The same over two `g2p eval seg --json` files (`g2p eval compare A.json
// B.json`, g2p.compare_segmentation_files); kNotFound "PATH: cannot open"
// when one cannot be read.
G2P_API Result<SegmentationComparison> compare_segmentation_files(const std::string& path_a, const std::string& path_b,
                                                                  const SegmentationComparisonOptions& options = {});

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

// mass_errors over a CSV of predictions (`g2p eval mass`): a header that
// starts object,predicted_kg,true_kg, then one object a row (more columns
// are ignored; empty lines skipped). Errors name the file and the line.
G2P_API Result<MassErrors> mass_errors_from_csv(const std::string& path);

// {"objects": ..., "ade_kg": ..., "alde": ..., "ape": ..., "mnre": ...},
// indented, without a final newline (`g2p eval mass --json`).
G2P_API std::string mass_errors_json(const MassErrors& errors);

}  // namespace g2p
