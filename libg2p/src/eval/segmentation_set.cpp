// segmentation_set: a segmenter scored over a labelled set of models (the
// paper's Table 2; `g2p eval seg`). Each model runs through Pipeline from
// render to project or refine; labels.json is read once per set.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "g2p/eval.h"
#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/regions.h"
#include "g2p/segment.h"

namespace g2p {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string truth_path(const SegmentationEvalOptions& o) {
  return o.truth.empty() ? (fs::path(o.assets) / "labels.json").string() : o.truth;
}

// labels.json, parsed once: its "models" object.
struct Truth {
  std::string path;
  json models;
};

Result<Truth> read_truth(const SegmentationEvalOptions& o) {
  Truth t;
  t.path = truth_path(o);
  std::ifstream in(t.path, std::ios::binary);
  if (!in)
    return Status::NotFound(t.path + ": cannot open the ground truth (--assets DIR holding labels.json, or --truth)");
  std::ostringstream text;
  text << in.rdbuf();
  json doc = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("models") || !doc["models"].is_object())
    return Status::ParseError(t.path + ": expected {\"models\": {...}}");
  t.models = std::move(doc["models"]);
  return t;
}

// The keys to score: the options' (each must be in the truth), else every
// key of the split.
Result<std::vector<std::string>> keys_to_score(const SegmentationEvalOptions& o, const Truth& truth) {
  std::vector<std::string> keys;
  if (!o.models.empty()) {
    for (const std::string& key : o.models)
      if (!truth.models.contains(key)) {
        std::string known;
        for (const auto& item : truth.models.items()) known += (known.empty() ? "" : ", ") + item.key();
        return Status::NotFound(truth.path + ": no model '" + key + "' (--models; known: " + known + ")");
      }
    return o.models;
  }
  for (const auto& item : truth.models.items())
    if (o.split.empty() || (item.value().is_object() && item.value().value("split", "") == o.split))
      keys.push_back(item.key());
  if (keys.empty())
    return Status::NotFound(truth.path + ": no model" +
                            (o.split.empty() ? "" : " of split '" + o.split + "' (--split)"));
  return keys;
}

// The class of every source material of one model, from its entry.
Result<std::vector<int>> material_truth(const Truth& truth, const std::string& key, const MaterialTable& table,
                                        int num_materials) {
  const json& entry = truth.models.at(key);
  if (!entry.is_object() || !entry.contains("labels"))
    return Status::ParseError(truth.path + ": model '" + key + "': expected {\"labels\": {...}}");
  const json bare = {{"labels", entry["labels"]}};
  Result<std::vector<int>> labels = material_labels_from_json(bare.dump(), key, table, num_materials);
  if (!labels.ok()) return labels.status().with_context(truth.path + ": model '" + key + "'");
  return labels;
}

// A key that is a model file's path relative to `assets` (a generated
// dataset's labels.json), else the shared assets' KEY/KEY.glb.
std::string model_path(const std::string& assets, const std::string& key) {
  const fs::path as_file = fs::path(assets) / key;
  return fs::is_regular_file(as_file) ? as_file.string() : (fs::path(assets) / key / (key + ".glb")).string();
}

// The pixels' truth: the class of the face each pixel sees.
Result<ImageI32> pixel_truth(const View& view, const std::vector<int>& face_truth) {
  const int w = view.face_id.width(), h = view.face_id.height();
  ImageI32 truth;
  truth.reset(w, h, 1, kUnknownLabel);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int face = view.face_id.at(x, y);
      if (face < 0) continue;
      if (face >= static_cast<int>(face_truth.size()))
        return Status::InvalidArgument("face ID " + std::to_string(face) + " is not a face of the model");
      truth.at(x, y) = face_truth[static_cast<std::size_t>(face)];
    }
  return truth;
}

std::string quoted_csv(const std::string& s) {  // RFC 4180: always quoted, quotes doubled
  std::string out = "\"";
  for (const char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + '"';
}

// The regions of one model with their features (regions.h) and their true
// class: the class of most of the region's labelled area, with that share and
// the labelled share of the region, for training and checking the region
// classifier. Refining changes neither the face graph nor the votes.
Status write_region_rows(std::ostream& out, const std::string& key, const Mesh& mesh, const std::vector<View>& views,
                         const Projection& projection, const std::vector<int>& face_truth, const MaterialTable& table) {
  const FaceColours colours = face_colours(mesh, views);
  Result<Regions> regions = find_regions(mesh, projection.graph, colours);
  if (!regions.ok()) return regions.status();
  Result<std::vector<float>> features = region_features(mesh, *regions, projection.votes, colours, table);
  if (!features.ok()) return features.status();
  const std::size_t width = region_feature_names(table).size();
  double total = 0.0;
  for (const Region& r : regions->regions) total += r.area_m2;
  std::vector<double> by_class(static_cast<std::size_t>(table.size()));
  const std::string quoted_key = quoted_csv(key);
  for (std::size_t r = 0; r < regions->regions.size(); ++r) {
    const Region& region = regions->regions[r];
    std::fill(by_class.begin(), by_class.end(), 0.0);
    double labelled = 0.0;
    for (const int f : region.faces) {
      const int t = face_truth[static_cast<std::size_t>(f)];
      if (t < 0 || t >= table.size()) continue;
      const double a = face_area(mesh, f);
      by_class[static_cast<std::size_t>(t)] += a;
      labelled += a;
    }
    const auto best = std::max_element(by_class.begin(), by_class.end());
    const bool known = labelled > 0.0 && *best > 0.0;
    out << quoted_key << ',' << r << ',' << region.faces.size() << ',' << (total > 0 ? region.area_m2 / total : 0.0)
        << ',' << (known ? table[static_cast<int>(best - by_class.begin())].name : std::string()) << ','
        << (known ? *best / labelled : 0.0) << ',' << (region.area_m2 > 0 ? labelled / region.area_m2 : 0.0);
    for (std::size_t i = 0; i < width; ++i) out << ',' << (*features)[r * width + i];
    out << '\n';
  }
  return out ? Status::Ok() : Status::IoError("writing the region features failed");
}

json matrix_json(const ConfusionMatrix& m, const MaterialTable& table) { return json::parse(m.to_json(table)); }

}  // namespace

struct SegmentationEvaluator::Impl {
  SegmentationEvalOptions options;
  bool prepared = false;
  Pipeline pipeline;
  std::shared_ptr<Segmenter> segmenter;  // the scored backend (its warnings are read after each model)
  std::unique_ptr<Identifier> names;     // object_from_names: the model's own names
  std::vector<std::string> warned;       // the segmenter's warnings said so far

  PipelineOptions pipeline_options() const;
  Status score_model(const std::string& key, const Truth& truth, std::ostream* region_rows, RunContext* context,
                     SegmentationEval& out, SegmentationModelEval& scored);
};

PipelineOptions SegmentationEvaluator::Impl::pipeline_options() const {
  const SegmentationEvalOptions& o = options;
  PipelineOptions p;
  p.anonymize_names = o.anonymize_names;
  p.base_color_only = o.base_color_only;
  p.renderer = o.renderer;
  p.views = o.views;
  p.identifier = o.identifier;
  p.kind_confidence = o.kind_confidence;
  p.kind_prior = o.kind_prior;
  p.size_policy = SizePolicy::kFile;  // scores per face by area: the file's size, never the kind's
  p.segmenter = o.segmenter;          // set_segmenter gives the object made from it
  p.project = o.project;
  p.refiner = o.refiner;
  p.last_stage = o.refiner.name == "none" ? Stage::kProject : Stage::kRefine;
  p.measure_stage_memory = false;
  return p;
}

SegmentationEvaluator::SegmentationEvaluator(SegmentationEvalOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
}
SegmentationEvaluator::~SegmentationEvaluator() = default;
SegmentationEvaluator::SegmentationEvaluator(SegmentationEvaluator&&) noexcept = default;
SegmentationEvaluator& SegmentationEvaluator::operator=(SegmentationEvaluator&&) noexcept = default;

const SegmentationEvalOptions& SegmentationEvaluator::options() const { return impl_->options; }

Status SegmentationEvaluator::prepare() {
  Impl& m = *impl_;
  if (m.prepared) return Status::Ok();
  const SegmentationEvalOptions& o = m.options;
  if (o.materials.size() == 0)
    return Status::InvalidArgument("materials (--materials): the material table has no classes");
  if (o.refiner.name == "none" && !o.refiner.settings.empty())
    return Status::InvalidArgument("refiner settings (--refine-set) need a refiner other than none (--refiner; got '" +
                                   o.refiner.settings.begin()->first + "')");
  if (o.object_from_names && o.identifier.name == "none")
    return Status::InvalidArgument(
        "object_from_names (--object-from-names) needs an identifier that reads the user's words (--identifier auto "
        "or object)");
  // The backends are made here, so that their errors name the flag, and the
  // segmenter is kept to read its warnings after each model.
  Result<std::unique_ptr<Segmenter>> segmenter = make_segmenter(o.segmenter.name, o.segmenter.settings);
  if (!segmenter.ok()) return segmenter.status().with_context("--segmenter " + o.segmenter.name);
  Result<std::unique_ptr<Identifier>> identifier = make_identifier(o.identifier.name, o.identifier.settings);
  if (!identifier.ok()) return identifier.status().with_context("--identifier " + o.identifier.name);
  std::unique_ptr<Refiner> refiner;
  if (o.refiner.name != "none") {
    Result<std::unique_ptr<Refiner>> made = make_refiner(o.refiner.name, o.refiner.settings);
    if (!made.ok()) return made.status().with_context("--refiner " + o.refiner.name);
    refiner = std::move(*made);
  }
  if (o.object_from_names) {
    Result<std::unique_ptr<Identifier>> names = make_identifier("names");
    if (!names.ok()) return names.status().with_context("--object-from-names");
    m.names = std::move(*names);
  }
  m.segmenter = std::move(*segmenter);
  m.pipeline = Pipeline(m.pipeline_options());
  m.pipeline.set_segmenter(m.segmenter);
  m.pipeline.set_identifier(std::move(*identifier));
  m.pipeline.set_refiner(std::move(refiner));
  m.pipeline.set_material_table(o.materials);
  G2P_RETURN_IF_ERROR(m.pipeline.prepare());
  m.prepared = true;
  return Status::Ok();
}

Status SegmentationEvaluator::Impl::score_model(const std::string& key, const Truth& truth, std::ostream* region_rows,
                                                RunContext* context, SegmentationEval& out,
                                                SegmentationModelEval& scored) {
  const SegmentationEvalOptions& o = options;
  const MaterialTable& table = o.materials;
  Result<Model> model = load_model(model_path(o.assets, key));
  if (!model.ok()) return model.status();
  const int num_materials = static_cast<int>(model->materials.size());
  Result<std::vector<int>> materials = material_truth(truth, key, table, num_materials);
  if (!materials.ok()) return materials.status();
  // The user's words, as the model's own names give them (before the run removes them).
  pipeline.options().object.clear();
  if (names != nullptr) {
    IdentifyInput in;
    in.model = &*model;
    Result<Identification> named = names->identify(in);
    if (named.ok() && named->known()) pipeline.options().object = named->kind();
  }
  Result<PipelineResult> run = pipeline.run(std::move(*model), context);
  if (!run.ok()) return run.status();
  const PipelineResult& r = *run;
  const Mesh& mesh = r.model.mesh;

  // A backend that degraded says why, once per set: its scores are not its own.
  for (const std::string& w : segmenter->warnings())
    if (std::find(warned.begin(), warned.end(), w) == warned.end()) {
      warned.push_back(w);
      scored.warnings.push_back(w);
    }
  scored.key = key;
  if (!r.kind.name.empty()) {
    scored.kind = r.kind.name;
    scored.kind_prior_applied = !kind_class_prior(r.kind, table, o.kind_prior).empty();
  }

  // Ground truth per face from its source material.
  std::vector<int> face_truth(mesh.triangles.size(), kUnknownLabel);
  for (std::size_t f = 0; f < face_truth.size() && f < mesh.face_source.size(); ++f) {
    const int m = mesh.face_source[f].material;
    if (m >= 0 && m < num_materials) face_truth[f] = (*materials)[static_cast<std::size_t>(m)];
  }

  // 2D: every pixel of every view.
  scored.pixels = ConfusionMatrix(table.size());
  for (std::size_t i = 0; i < r.views.size() && i < r.label_maps.size(); ++i) {
    const LabelMap& predicted = r.label_maps[i];
    Result<ImageI32> pixels = pixel_truth(r.views[i], face_truth);
    if (!pixels.ok()) return pixels.status().with_context("view " + std::to_string(i));
    G2P_RETURN_IF_ERROR(scored.pixels.add(*pixels, predicted.labels).with_context("view " + std::to_string(i)));
    if (!predicted.probabilities.empty())
      G2P_RETURN_IF_ERROR(out.calibration.add(*pixels, predicted.labels, predicted.probabilities)
                              .with_context("view " + std::to_string(i)));
  }

  if (region_rows != nullptr)
    G2P_RETURN_IF_ERROR(write_region_rows(*region_rows, key, mesh, r.views, r.projection, face_truth, table)
                            .with_context("--region-features " + o.region_features));

  // The refine stage's report: notes and changes, or why it failed.
  if (o.refiner.name != "none") {
    scored.refined = true;
    const StageReport* stage = r.stage(Stage::kRefine);
    if (stage != nullptr && !stage->ok && !r.refinement.fell_back) {
      scored.refine_error = stage->error;
      scored.warnings.push_back("refine failed, keeping the projected labels: " + stage->error);
    } else {
      scored.refine_notes = r.refinement.notes;
      scored.refine_changed_faces = r.refinement.changes.size();
    }
  }

  // 3D: the faces' labels after voting (and refining), by area.
  scored.faces = ConfusionMatrix(table.size());
  return scored.faces.add_faces(mesh, face_truth, r.projection.labels.label);
}

Result<SegmentationEval> SegmentationEvaluator::run(RunContext* context) {
  G2P_RETURN_IF_ERROR(prepare());
  Impl& m = *impl_;
  const SegmentationEvalOptions& o = m.options;
  Result<Truth> truth = read_truth(o);
  if (!truth.ok()) return truth.status();
  Result<std::vector<std::string>> keys = keys_to_score(o, *truth);
  if (!keys.ok()) return keys.status();

  std::ofstream region_rows;
  if (!o.region_features.empty()) {
    region_rows.open(o.region_features, std::ios::binary | std::ios::trunc);
    if (!region_rows) return Status::IoError("--region-features " + o.region_features + ": cannot be written");
    region_rows << "model,region,faces,area_share,truth,truth_share,labelled_share";
    for (const std::string& name : region_feature_names(o.materials)) region_rows << ',' << name;
    region_rows << '\n';
  }

  SegmentationEval out;
  out.options = o;
  const int classes = o.materials.size();
  out.total = out.total_3d = out.total_3d_per_model = ConfusionMatrix(classes);
  m.warned.clear();
  std::vector<ConfusionMatrix> per_model_3d;
  for (const std::string& key : *keys) {
    if (context != nullptr && context->cancelled()) return Status::Cancelled("cancelled before " + key);
    SegmentationModelEval scored;
    G2P_RETURN_IF_ERROR(m.score_model(key, *truth, region_rows.is_open() ? &region_rows : nullptr, context, out, scored)
                            .with_context(key));
    out.total.merge(scored.pixels);
    out.total_3d.merge(scored.faces);
    // Each model scaled to one, so that none dominates by its size or units
    // (sweethome3d models range from millimetres to metres).
    if (scored.faces.total() > 0) out.total_3d_per_model.merge(scored.faces, 1.0 / scored.faces.total());
    per_model_3d.push_back(scored.faces);
    out.models.push_back(std::move(scored));
    if (o.on_model) o.on_model(out.models.back());
  }
  Result<MeanIouInterval> interval = bootstrap_mean_iou(per_model_3d);
  if (interval.ok()) out.interval = *interval;
  return out;
}

Result<SegmentationEval> evaluate_segmentation(const SegmentationEvalOptions& options, RunContext* context) {
  return SegmentationEvaluator(options).run(context);
}

std::string SegmentationEval::to_text() const {
  const MaterialTable& classes = options.materials;
  std::ostringstream out;
  char line[256];
  std::snprintf(line, sizeof line, "All %zu models, one confusion matrix (%.0f labelled pixels), IoU %%:\n",
                models.size(), total.total());
  out << line << total.table(classes) << "\nPer face (3D, weighted by area, after voting), IoU %:\n"
      << total_3d.table(classes) << "\nPer face (3D, after voting), each model weighing the same, IoU %:\n"
      << total_3d_per_model.table(classes);
  if (interval) {
    std::snprintf(line, sizeof line,
                  "mIoU %.2f %%, %.0f %% interval over models %.2f-%.2f %% (bootstrap, %d resamples of %zu models)\n",
                  100.0 * interval->miou, 100.0 * interval->confidence, 100.0 * interval->low, 100.0 * interval->high,
                  interval->resamples, models.size());
    out << line;
  }
  if (calibration.accuracy() == calibration.accuracy()) {  // has probabilities
    std::snprintf(line, sizeof line, "calibration: mean confidence %.3f, accuracy %.3f, ECE %.3f (10 bins)\n",
                  calibration.mean_confidence(), calibration.accuracy(), calibration.expected_calibration_error());
    out << line;
  }
  return out.str();
}

std::string SegmentationEval::to_json() const {
  const MaterialTable& table = options.materials;
  json per_model = json::object();
  for (const SegmentationModelEval& m : models) {
    json entry = {{"2d", matrix_json(m.pixels, table)},
                  {"3d", matrix_json(m.faces, table)},
                  {"kind", m.kind},
                  {"kind_prior_applied", m.kind_prior_applied}};
    if (m.refined) {
      json refine = {{"refiner", options.refiner.name}};
      if (!m.refine_error.empty()) {
        refine["error"] = m.refine_error;
      } else {
        refine["notes"] = m.refine_notes;
        refine["changed_faces"] = m.refine_changed_faces;
      }
      entry["refine"] = std::move(refine);
    }
    per_model[m.key] = std::move(entry);
  }
  std::vector<std::string> refine_settings;
  for (const auto& [k, v] : options.refiner.settings) refine_settings.push_back(k + "=" + v);
  const json doc = {{"segmenter", options.segmenter.name},
                    {"anonymized_names", options.anonymize_names},
                    {"base_color_only", options.base_color_only},
                    {"vote", options.project.vote.mode == VoteMode::kSoft ? "soft" : "hard"},
                    {"refiner", options.refiner.name},
                    {"refine_settings", refine_settings},
                    {"views", options.views.num_views},
                    {"resolution", options.views.width},
                    {"total", matrix_json(total, table)},
                    {"total_3d", matrix_json(total_3d, table)},
                    {"total_3d_per_model", matrix_json(total_3d_per_model, table)},
                    {"total_3d_per_model_interval", interval ? json{{"low", interval->low},
                                                                    {"high", interval->high},
                                                                    {"confidence", interval->confidence},
                                                                    {"resamples", interval->resamples}}
                                                             : json(nullptr)},
                    {"calibration",
                     {{"ece", calibration.expected_calibration_error()},
                      {"mean_confidence", calibration.mean_confidence()},
                      {"accuracy", calibration.accuracy()}}},
                    {"models", per_model}};
  // Names that are not UTF-8 (a Latin-1 file name) become U+FFFD rather than throwing.
  return doc.dump(2, ' ', false, json::error_handler_t::replace);
}

}  // namespace g2p
