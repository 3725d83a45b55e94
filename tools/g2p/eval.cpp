// g2p eval seg: segmentation accuracy over a labelled set of models, as the
// paper's Table 2 (one confusion matrix over the set, IoU per class, mIoU).
// g2p eval mass: mass errors over a CSV of predictions, as the paper's Table 1.
// g2p eval compare: whether one segmenter beats another on the same models (a paired bootstrap of two eval seg
// --json files).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "common.h"
#include "g2p/eval.h"
#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/pipeline.h"
#include "g2p/project.h"
#include "g2p/regions.h"
#include "g2p/segment.h"
#include "json_out.h"
#include "stage_outputs.h"

namespace g2p::cli {
namespace {

struct EvalArgs {
  std::string assets;  // folder with labels.json and NAME/NAME.glb
  std::vector<std::string> models;
  ViewArgs views;
  SegmenterArgs segmenter;
  std::string materials;
  bool anonymize = false;
  bool base_color_only = false;
  std::string truth;  // labels.json elsewhere than in `assets`
  std::string split;  // only models whose entry has this "split"
  std::string json_out;
  bool soft = false;            // soft votes (the segmenter's probabilities) instead of one vote per pixel
  RefineArgs refine;            // the refine stage after voting (default none: the project stage alone)
  std::string region_features;  // CSV of every region's features and true class (training the region classifier)
  // What the object is, as `g2p run` finds it, and what its kind's materials weigh.
  std::string identifier = "none";
  bool object_from_names = false;  // the names identifier on the model as given stands for the user's --object
  double kind_confidence = PipelineOptions{}.kind_confidence;
  double kind_prior = PipelineOptions{}.kind_prior;
};

// The regions of one model with their features (regions.h) and their true
// class: the class of most of the region's labelled area, with that share and
// the labelled share of the region, for training and checking the region
// classifier.
Status write_region_rows(std::ostream& out, const std::string& key, const Model& model, const std::vector<View>& views,
                         const Projection& projection, const std::vector<int>& face_truth, const MaterialTable& table) {
  const FaceColours colours = face_colours(model.mesh, views);
  Result<Regions> regions = find_regions(model.mesh, projection.graph, colours);
  if (!regions.ok()) return regions.status();
  Result<std::vector<float>> features = region_features(model.mesh, *regions, projection.votes, colours, table);
  if (!features.ok()) return features.status();
  const std::size_t width = region_feature_names(table).size();
  double total = 0.0;
  for (const Region& r : regions->regions) total += r.area_m2;
  std::vector<double> by_class(static_cast<std::size_t>(table.size()));
  std::string quoted_key = "\"";  // RFC 4180: always quoted, quotes doubled
  for (const char c : key) quoted_key += c == '"' ? std::string("\"\"") : std::string(1, c);
  quoted_key += '"';
  for (std::size_t r = 0; r < regions->regions.size(); ++r) {
    const Region& region = regions->regions[r];
    std::fill(by_class.begin(), by_class.end(), 0.0);
    double labelled = 0.0;
    for (const int f : region.faces) {
      const int t = face_truth[static_cast<std::size_t>(f)];
      if (t < 0 || t >= table.size()) continue;
      const double a = face_area(model.mesh, f);
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

int run_eval_seg(const EvalArgs& args) {
  namespace fs = std::filesystem;
  const std::string labels_path = args.truth.empty() ? (fs::path(args.assets) / "labels.json").string() : args.truth;
  std::ifstream in(labels_path, std::ios::binary);
  if (!in) {
    std::cerr << "g2p eval seg: error: " << labels_path << ": cannot open (use --assets DIR)\n";
    return kExitFailure;
  }
  std::ostringstream text;
  text << in.rdbuf();
  const nlohmann::json labels = nlohmann::json::parse(text.str(), nullptr, false);
  if (labels.is_discarded() || !labels.contains("models") || !labels["models"].is_object()) {
    std::cerr << "g2p eval seg: error: " << labels_path << ": expected {\"models\": {...}}\n";
    return kExitFailure;
  }
  std::vector<std::string> keys = args.models;
  if (keys.empty())
    for (const auto& item : labels["models"].items())
      if (args.split.empty() || (item.value().is_object() && item.value().value("split", "") == args.split))
        keys.push_back(item.key());
  if (keys.empty()) {
    std::cerr << "g2p eval seg: error: " << labels_path << ": no model"
              << (args.split.empty() ? "" : " of split '" + args.split + "'") << "\n";
    return kExitFailure;
  }

  int exit_code = kExitOk;
  Result<MaterialTable> table = load_table_flag("eval seg", args.materials, exit_code);
  if (!table.ok()) return exit_code;
  Result<std::unique_ptr<Segmenter>> predictor = make_segmenter_flag("eval seg", args.segmenter, exit_code);
  if (!predictor.ok()) return exit_code;
  Result<std::unique_ptr<Refiner>> refiner = make_refiner_flag("eval seg", args.refine, exit_code);
  if (!refiner.ok()) return exit_code;
  const ObjectTable& objects = ObjectTable::shipped();
  std::unique_ptr<Identifier> identifier, names_identifier;
  for (auto [name, slot] : {std::pair<std::string, std::unique_ptr<Identifier>*>{args.identifier, &identifier},
                            {args.object_from_names ? "names" : "none", &names_identifier}}) {
    if (name == "none") continue;
    Result<std::unique_ptr<Identifier>> made = make_identifier(name);
    if (!made.ok()) {
      std::cerr << "g2p eval seg: error: --identifier " << name << ": " << made.status().message() << "\n";
      return kExitUsage;
    }
    *slot = std::move(*made);
  }
  if (args.object_from_names && identifier == nullptr) {
    std::cerr << "g2p eval seg: error: --object-from-names needs an --identifier that reads the user's words (auto "
                 "or object)\n";
    return kExitUsage;
  }
  std::ofstream region_rows;
  if (!args.region_features.empty()) {
    region_rows.open(args.region_features, std::ios::binary | std::ios::trunc);
    if (!region_rows) {
      std::cerr << "g2p eval seg: error: --region-features " << args.region_features << ": cannot be written\n";
      return kExitFailure;
    }
    region_rows << "model,region,faces,area_share,truth,truth_share,labelled_share";
    for (const std::string& name : region_feature_names(*table)) region_rows << ',' << name;
    region_rows << '\n';
  }

  // total_3d pools every face by its area; per_model_3d scales each model's
  // matrix to one first, so that no model dominates by its size or units
  // (sweethome3d models range from millimetres to metres).
  ConfusionMatrix total(table->size()), total_3d(table->size()), per_model_3d(table->size());
  CalibrationBins calibration;
  nlohmann::json per_model = nlohmann::json::object();
  std::vector<ConfusionMatrix> model_matrices_3d;  // for the bootstrap interval
  std::vector<std::string> warned;                 // the predictor's warnings shown so far
  for (const std::string& key : keys) {
    // A key that is a model file's path relative to `assets` (a generated
    // dataset's labels.json), else the shared assets' NAME/NAME.glb.
    const fs::path as_file = fs::path(args.assets) / key;
    const std::string path =
        fs::is_regular_file(as_file) ? as_file.string() : (fs::path(args.assets) / key / (key + ".glb")).string();
    Result<Model> model = load_model(path);
    if (!model.ok()) {
      std::cerr << "g2p eval seg: error: " << model.status().to_string() << "\n";
      return kExitFailure;
    }
    Result<std::unique_ptr<Segmenter>> oracle = make_segmenter("oracle", {{"labels", labels_path}, {"key", key}});
    Status s = oracle.ok() ? (*oracle)->set_model(*model, *table) : oracle.status();
    if (!s.ok()) {
      std::cerr << "g2p eval seg: error: " << s.to_string() << "\n";
      return kExitFailure;
    }
    // The user's words, as the model's own names give them (before they are removed).
    std::string object_text;
    if (args.object_from_names) {
      IdentifyInput names_in;
      names_in.model = &*model;
      Result<Identification> named = names_identifier->identify(names_in);
      if (named.ok() && named->known()) object_text = named->kind();
    }
    if (args.anonymize) anonymize_names(*model);  // after the oracle: it reads indices, not names
    if (args.base_color_only) reduce_to_base_color(*model);
    Result<std::vector<View>> views = render_with_flags("eval seg", *model, args.views, exit_code);
    if (!views.ok()) return exit_code;
    if (s = (*predictor)->set_model(*model, *table); !s.ok()) {
      std::cerr << "g2p eval seg: error: " << key << ": " << s.to_string() << "\n";
      return kExitFailure;
    }
    const std::vector<std::uint8_t> image_decided = (*predictor)->image_decided_faces();
    // What the object is, as g2p run identifies it; a confident kind's
    // materials weigh the classes read from the image.
    std::string kind = "unknown";
    std::vector<float> class_prior;
    if (identifier != nullptr) {
      IdentifyInput id_in;
      id_in.model = &*model;
      id_in.views = &*views;
      id_in.object_text = object_text;
      id_in.use_file_name = !args.anonymize;
      Result<std::unique_ptr<Renderer>> turntable = renderer_registry().create("embree");
      if (turntable.ok() && (*turntable)->set_model(*model).ok()) id_in.renderer = turntable->get();
      Result<Identification> id = identifier->identify(id_in);
      if (!id.ok()) {
        std::cerr << "g2p eval seg: error: " << key << ": " << id.status().to_string() << "\n";
        return kExitFailure;
      }
      const int k = id->known() && id->confidence() >= args.kind_confidence ? objects.find(id->kind()) : -1;
      if (k >= 0) {
        kind = id->kind();
        class_prior = kind_class_prior(objects.kinds()[static_cast<std::size_t>(k)], *table, args.kind_prior);
      }
    }
    // A backend that degraded says why, once: its scores are not its own.
    for (const std::string& w : (*predictor)->warnings())
      if (std::find(warned.begin(), warned.end(), w) == warned.end()) {
        std::cerr << "g2p eval seg: warning: " << w << "\n";
        warned.push_back(w);
      }
    ConfusionMatrix matrix(table->size());
    LabelMap truth, predicted;
    std::vector<LabelMap> predictions;
    for (const View& v : *views) {
      s = (*oracle)->segment_into(v, truth);
      if (s.ok()) s = (*predictor)->segment_into(v, predicted);
      if (s.ok() && !class_prior.empty()) s = apply_class_prior(class_prior, image_decided, v, predicted).status();
      if (s.ok()) s = matrix.add(truth.labels, predicted.labels);
      if (s.ok() && !predicted.probabilities.empty())
        s = calibration.add(truth.labels, predicted.labels, predicted.probabilities);
      predictions.push_back(predicted);
      if (!s.ok()) {
        std::cerr << "g2p eval seg: error: " << key << ": " << s.to_string() << "\n";
        return kExitFailure;
      }
    }
    // 3D: the predictions voted onto the faces (the project stage), scored per
    // face weighted by area; ground truth per face from its source material.
    ProjectOptions project_options;
    project_options.vote.mode = args.soft ? VoteMode::kSoft : VoteMode::kHard;
    Result<Projection> projection = project(model->mesh, *views, predictions, table->size(), project_options);
    if (!projection.ok()) {
      std::cerr << "g2p eval seg: error: " << key << ": " << projection.status().to_string() << "\n";
      return kExitFailure;
    }
    Result<std::vector<int>> material_truth =
        material_labels_from_json(text.str(), key, *table, static_cast<int>(model->materials.size()));
    if (!material_truth.ok()) {
      std::cerr << "g2p eval seg: error: " << material_truth.status().to_string() << "\n";
      return kExitFailure;
    }
    std::vector<int> face_truth(model->mesh.triangles.size(), kUnknownLabel);
    for (std::size_t f = 0; f < face_truth.size(); ++f) {
      const int m = model->mesh.face_source[f].material;
      if (m >= 0 && m < static_cast<int>(material_truth->size())) face_truth[f] = (*material_truth)[m];
    }
    if (region_rows.is_open())
      if (Status st = write_region_rows(region_rows, key, *model, *views, *projection, face_truth, *table); !st.ok()) {
        std::cerr << "g2p eval seg: error: --region-features " << args.region_features << ": " << key << ": "
                  << st.to_string() << "\n";
        return kExitFailure;
      }
    nlohmann::json refine_report;  // kept in the JSON, not printed: the table stays one line per model
    if (const int code = apply_refiner("eval seg", args.refine.name, refiner->get(), *model, *views, *table,
                                       project_options.partition, *projection, refine_report, /*print_notes=*/false,
                                       &image_decided, &class_prior);
        code != kExitOk)
      return code;
    ConfusionMatrix matrix_3d(table->size());
    if (Status st = matrix_3d.add_faces(model->mesh, face_truth, projection->labels.label); !st.ok()) {
      std::cerr << "g2p eval seg: error: " << st.to_string() << "\n";
      return kExitFailure;
    }
    total.merge(matrix);
    total_3d.merge(matrix_3d);
    if (matrix_3d.total() > 0) per_model_3d.merge(matrix_3d, 1.0 / matrix_3d.total());
    model_matrices_3d.push_back(matrix_3d);
    std::printf(
        "%-28s 2D: %9.0f px, accuracy %6.2f %%, mIoU %6.2f %% | 3D: %8.4f m^2, accuracy %6.2f %%, mIoU %6.2f %%\n",
        key.c_str(), matrix.total(), 100.0 * matrix.accuracy(), 100.0 * matrix.mean_iou(), matrix_3d.total(),
        100.0 * matrix_3d.accuracy(), 100.0 * matrix_3d.mean_iou());
    per_model[key] = {{"2d", nlohmann::json::parse(matrix.to_json(*table))},
                      {"3d", nlohmann::json::parse(matrix_3d.to_json(*table))},
                      {"kind", kind},
                      {"kind_prior_applied", !class_prior.empty()}};
    if (refiner->get() != nullptr) {
      refine_report.erase("changes_first_1000");  // per face: too long for a score file
      per_model[key]["refine"] = refine_report;
    }
  }
  std::printf("\nAll %zu models, one confusion matrix (%.0f labelled pixels), IoU %%:\n", keys.size(), total.total());
  std::cout << total.table(*table) << "\nPer face (3D, weighted by area, after voting), IoU %:\n"
            << total_3d.table(*table) << "\nPer face (3D, after voting), each model weighing the same, IoU %:\n"
            << per_model_3d.table(*table);
  const Result<MeanIouInterval> interval = bootstrap_mean_iou(model_matrices_3d);
  if (interval.ok())
    std::printf("mIoU %.2f %%, %.0f %% interval over models %.2f-%.2f %% (bootstrap, %d resamples of %zu models)\n",
                100.0 * interval->miou, 100.0 * interval->confidence, 100.0 * interval->low, 100.0 * interval->high,
                interval->resamples, model_matrices_3d.size());
  if (calibration.accuracy() == calibration.accuracy())  // has probabilities
    std::printf("calibration: mean confidence %.3f, accuracy %.3f, ECE %.3f (10 bins)\n", calibration.mean_confidence(),
                calibration.accuracy(), calibration.expected_calibration_error());
  if (!args.json_out.empty()) {
    const nlohmann::json doc = {
        {"segmenter", args.segmenter.name},
        {"anonymized_names", args.anonymize},
        {"base_color_only", args.base_color_only},
        {"vote", args.soft ? "soft" : "hard"},
        {"refiner", args.refine.name},
        {"refine_settings", args.refine.settings},
        {"views", args.views.views},
        {"resolution", args.views.resolution},
        {"total", nlohmann::json::parse(total.to_json(*table))},
        {"total_3d", nlohmann::json::parse(total_3d.to_json(*table))},
        {"total_3d_per_model", nlohmann::json::parse(per_model_3d.to_json(*table))},
        {"total_3d_per_model_interval", interval.ok() ? nlohmann::json{{"low", interval->low},
                                                                       {"high", interval->high},
                                                                       {"confidence", interval->confidence},
                                                                       {"resamples", interval->resamples}}
                                                      : nlohmann::json(nullptr)},
        {"calibration",
         {{"ece", calibration.expected_calibration_error()},
          {"mean_confidence", calibration.mean_confidence()},
          {"accuracy", calibration.accuracy()}}},
        {"models", per_model}};
    std::ofstream out(args.json_out, std::ios::binary | std::ios::trunc);
    out << json_out(doc) << "\n";
    if (!out) {
      std::cerr << "g2p eval seg: error: " << args.json_out << ": cannot write\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

}  // namespace

struct MassArgs {
  std::string csv;
  std::string json_out;
};

// object,predicted_kg,true_kg (header required; extra columns ignored).
int run_eval_mass(const MassArgs& args) {
  std::ifstream in(args.csv, std::ios::binary);
  if (!in) {
    std::cerr << "g2p eval mass: error: " << args.csv << ": cannot open\n";
    return kExitFailure;
  }
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.rfind("object,predicted_kg,true_kg", 0) != 0) {
    std::cerr << "g2p eval mass: error: " << args.csv << ":1: the header must start object,predicted_kg,true_kg\n";
    return kExitFailure;
  }
  std::vector<std::string> names;
  std::vector<double> predicted, truth;
  for (int n = 2; std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::stringstream row(line);
    std::string name, p, t;
    std::getline(row, name, ',');
    std::getline(row, p, ',');
    std::getline(row, t, ',');
    char* end_p = nullptr;
    char* end_t = nullptr;
    const double pv = std::strtod(p.c_str(), &end_p), tv = std::strtod(t.c_str(), &end_t);
    if (end_p == p.c_str() || *end_p != '\0' || end_t == t.c_str() || *end_t != '\0') {
      std::cerr << "g2p eval mass: error: " << args.csv << ":" << n << ": expected two numbers, got '" << line << "'\n";
      return kExitFailure;
    }
    names.push_back(name);
    predicted.push_back(pv);
    truth.push_back(tv);
  }
  Result<MassErrors> e = mass_errors(predicted, truth);
  if (!e.ok()) {
    std::cerr << "g2p eval mass: error: " << args.csv << ": " << e.status().message() << "\n";
    return kExitFailure;
  }
  std::printf("%d objects: ADE %.4g kg, ALDE %.4f, APE %.4f, MnRE %.4f\n", e->objects, e->ade_kg, e->alde, e->ape,
              e->mnre);
  if (!args.json_out.empty()) {
    const nlohmann::json j = {
        {"objects", e->objects}, {"ade_kg", e->ade_kg}, {"alde", e->alde}, {"ape", e->ape}, {"mnre", e->mnre}};
    if (Status s = write_text_file(args.json_out, json_out(j) + "\n"); !s.ok()) {
      std::cerr << "g2p eval mass: error: " << s.to_string() << "\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

struct CompareArgs {
  std::string a, b;  // g2p eval seg --json files
  double confidence = 0.95;
  int resamples = 2000;
  std::string json_out;
};

// One `g2p eval seg --json` file: its settings and per-model 3D matrices.
struct ScoreFile {
  nlohmann::json doc;
  std::vector<std::string> keys;
  std::vector<ConfusionMatrix> matrices;
  std::vector<std::string> classes;
};

Result<ScoreFile> read_score_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  ScoreFile out;
  out.doc = nlohmann::json::parse(text.str(), nullptr, false);
  if (out.doc.is_discarded() || !out.doc.is_object() || !out.doc.contains("models") || !out.doc["models"].is_object())
    return Status::InvalidArgument(path + ": not a g2p eval seg --json file (no \"models\" object)");
  for (const auto& item : out.doc["models"].items()) {
    if (!item.value().is_object() || !item.value().contains("3d"))
      return Status::InvalidArgument(path + ": model " + item.key() + " has no \"3d\" matrix");
    Result<ConfusionMatrix> m = confusion_matrix_from_json(item.value()["3d"].dump(), path + ": " + item.key());
    if (!m.ok()) return m.status();
    if (out.classes.empty() && item.value()["3d"].contains("classes"))
      for (const auto& c : item.value()["3d"]["classes"])
        out.classes.push_back(c.is_string() ? c.get<std::string>() : "");
    out.keys.push_back(item.key());
    out.matrices.push_back(std::move(*m));
  }
  if (out.keys.empty()) return Status::InvalidArgument(path + ": scores no model");
  return out;
}

// What the two files were scored with, where it differs (not the segmenter: that is what is compared).
std::string differing_conditions(const nlohmann::json& a, const nlohmann::json& b) {
  std::string out;
  for (const char* key : {"anonymized_names", "base_color_only", "vote", "views", "resolution"})
    if (a.value(key, nlohmann::json()) != b.value(key, nlohmann::json()))
      out += std::string(out.empty() ? "" : ", ") + key + " (" + a.value(key, nlohmann::json()).dump() + " / " +
             b.value(key, nlohmann::json()).dump() + ")";
  return out;
}

// g2p eval compare: is B better than A on the same models? The paired bootstrap of the per-face mIoU difference
// (every model weighing the same), as docs/training.md's shipping rule asks.
int run_eval_compare(const CompareArgs& args) {
  Result<ScoreFile> a = read_score_file(args.a);
  Result<ScoreFile> b = a.ok() ? read_score_file(args.b) : Result<ScoreFile>(a.status());
  if (!b.ok()) {
    std::cerr << "g2p eval compare: error: " << b.status().message() << "\n";
    return kExitFailure;
  }
  // The same models on both sides, in A's order.
  std::vector<ConfusionMatrix> right;
  std::vector<std::string> only_a;
  for (std::size_t i = 0; i < a->keys.size(); ++i) {
    const auto at = std::find(b->keys.begin(), b->keys.end(), a->keys[i]);
    if (at == b->keys.end())
      only_a.push_back(a->keys[i]);
    else
      right.push_back(b->matrices[static_cast<std::size_t>(at - b->keys.begin())]);
  }
  if (!only_a.empty() || a->keys.size() != b->keys.size()) {
    std::cerr << "g2p eval compare: error: " << args.a << " and " << args.b << " score other models (" << a->keys.size()
              << " and " << b->keys.size() << " models"
              << (only_a.empty() ? ""
                                 : "; only in the first: " + only_a.front() +
                                       (only_a.size() > 1 ? " and " + std::to_string(only_a.size() - 1) + " more" : ""))
              << "); a paired comparison needs the same models\n";
    return kExitFailure;
  }
  Result<MeanIouDifference> d = bootstrap_mean_iou_difference(a->matrices, right, args.confidence, args.resamples);
  if (!d.ok()) {
    std::cerr << "g2p eval compare: error: " << d.status().message() << "\n";
    return kExitFailure;
  }
  const std::string differs = differing_conditions(a->doc, b->doc);
  if (!differs.empty()) std::cerr << "g2p eval compare: note: the files were scored differently: " << differs << "\n";
  const auto label = [](const ScoreFile& f) {
    std::string s = f.doc.value("segmenter", std::string("?"));
    if (f.doc.value("refiner", std::string()) != "" && f.doc.value("refiner", std::string()) != "none")
      s += " + " + f.doc.value("refiner", std::string());
    return s + ", " + f.doc.value("vote", std::string("?")) + " votes";
  };
  std::printf("A: %s (%s): mIoU %.2f %%\n", args.a.c_str(), label(*a).c_str(), 100.0 * d->miou_a);
  std::printf("B: %s (%s): mIoU %.2f %%\n", args.b.c_str(), label(*b).c_str(), 100.0 * d->miou_b);
  std::printf("B - A: %+.2f points, %.0f %% interval %+.2f to %+.2f (paired bootstrap, %d resamples of %d models)\n",
              100.0 * d->difference, 100.0 * d->confidence, 100.0 * d->low, 100.0 * d->high, d->resamples, d->models);
  std::printf("%s\n", d->low > 0.0    ? "B is better: the interval lies above zero"
                      : d->high < 0.0 ? "B is worse: the interval lies below zero"
                                      : "not resolved: the interval includes zero");
  // Per class, every model weighing the same.
  const int classes = a->matrices.front().num_classes();
  ConfusionMatrix sum_a(classes), sum_b(classes);
  for (std::size_t i = 0; i < right.size(); ++i) {
    if (a->matrices[i].total() <= 0) continue;
    sum_a.merge(a->matrices[i], 1.0 / a->matrices[i].total());
    sum_b.merge(right[i], 1.0 / right[i].total());
  }
  nlohmann::json per_class = nlohmann::json::object();
  std::printf(
      "\nPer face (3D), each model weighing the same, IoU %%:\n| class | A | B | B - A |\n|---|---:|---:|---:|\n");
  for (int c = 0; c < classes; ++c) {
    if (!sum_a.present(c)) continue;
    const std::string name = c < static_cast<int>(a->classes.size()) && !a->classes[static_cast<std::size_t>(c)].empty()
                                 ? a->classes[static_cast<std::size_t>(c)]
                                 : "class " + std::to_string(c);
    std::printf("| %s | %.1f | %.1f | %+.1f |\n", name.c_str(), 100.0 * sum_a.iou(c), 100.0 * sum_b.iou(c),
                100.0 * (sum_b.iou(c) - sum_a.iou(c)));
    per_class[name] = {{"a", sum_a.iou(c)}, {"b", sum_b.iou(c)}};
  }
  if (!args.json_out.empty()) {
    const nlohmann::json j = {{"a", args.a},
                              {"b", args.b},
                              {"miou_a", d->miou_a},
                              {"miou_b", d->miou_b},
                              {"difference", d->difference},
                              {"low", d->low},
                              {"high", d->high},
                              {"confidence", d->confidence},
                              {"resamples", d->resamples},
                              {"models", d->models},
                              {"iou_per_class", per_class}};
    if (Status s = write_text_file(args.json_out, json_out(j) + "\n"); !s.ok()) {
      std::cerr << "g2p eval compare: error: " << s.to_string() << "\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

void add_eval_command(CLI::App& app, Command& run) {
  CLI::App* eval = app.add_subcommand("eval", "Measure accuracy against ground truth");
  eval->require_subcommand(1);
  auto args = std::make_shared<EvalArgs>();
  CLI::App* seg = eval->add_subcommand(
      "seg", "Material segmentation accuracy over a labelled set: per pixel (2D) and per face after voting (3D)");
  seg->add_option("--assets", args->assets, "Folder with labels.json and NAME/NAME.glb (default ../shared/assets)")
      ->default_val("../shared/assets");
  seg->add_option("--models", args->models, "Only these models (keys of labels.json)")->delimiter(',');
  seg->add_option("--materials", args->materials, "Material table JSON (default: the paper's 12 classes)");
  seg->add_flag("--anonymize-names", args->anonymize, "Replace every name by a meaningless one before segmenting");
  seg->add_flag("--base-color-only", args->base_color_only,
                "Reduce every material to its base colour (metallic and roughness at glTF's defaults), as "
                "image-to-3D meshes are");
  seg->add_option("--truth", args->truth, "labels.json (default: ASSETS/labels.json); keys may be model paths");
  seg->add_option("--split", args->split, "Only the models whose labels.json entry has this \"split\"");
  seg->add_option("--json", args->json_out, "Also write the results as JSON to this file");
  add_view_flags(seg, args->views);
  add_segmenter_flags(seg, args->segmenter);
  seg->add_flag("--soft", args->soft, "Soft votes: add the segmenter's class probabilities instead of one vote");
  add_refiner_flags(seg, args->refine, "none");
  seg->add_option("--identifier", args->identifier,
                  "Identify each object as g2p run does (auto, names, detector, ...); a confident kind's materials "
                  "weigh the classes read from the image (--kind-prior). none: not identified")
      ->capture_default_str();
  seg->add_flag("--object-from-names", args->object_from_names,
                "Give each object's kind as the model's own names say it, before --anonymize-names removes them, "
                "as a user's --object would (the kind known, the names still removed for segmenting)");
  seg->add_option("--kind-confidence", args->kind_confidence, "The least identification confidence acted on")
      ->check(finite_number(0.0, 1.0))
      ->capture_default_str();
  seg->add_option("--kind-prior", args->kind_prior,
                  "Weight of the classes a confident kind does not list (1 = its materials are not used)")
      ->check(finite_number(0.0, 1.0, true))
      ->capture_default_str();
  seg->add_option("--region-features", args->region_features,
                  "Also write every region's features and true class to this CSV (training the region classifier, "
                  "docs/regions.md)");
  seg->callback([args, &run] { run = [args] { return run_eval_seg(*args); }; });

  auto margs = std::make_shared<MassArgs>();
  CLI::App* mass = eval->add_subcommand(
      "mass", "Mass errors (ADE, ALDE, APE, MnRE as in NeRF2Physics) over a CSV object,predicted_kg,true_kg");
  mass->add_option("csv", margs->csv, "CSV with the header object,predicted_kg,true_kg")->required();
  mass->add_option("--json", margs->json_out, "Also write the results as JSON to this file");
  mass->callback([margs, &run] { run = [margs] { return run_eval_mass(*margs); }; });

  auto cargs = std::make_shared<CompareArgs>();
  CLI::App* compare = eval->add_subcommand(
      "compare",
      "Is B better than A? The paired bootstrap interval of the per-face mIoU difference between two eval seg --json "
      "files that scored the same models");
  compare->add_option("a", cargs->a, "The reference: a g2p eval seg --json file")->required();
  compare->add_option("b", cargs->b, "The candidate: a g2p eval seg --json file of the same models")->required();
  compare->add_option("--confidence", cargs->confidence, "Interval coverage (default 0.95)")
      ->check(CLI::Range(0.5, 0.999));
  compare->add_option("--resamples", cargs->resamples, "Bootstrap resamples (default 2000)")
      ->check(CLI::Range(10, 1000000));
  compare->add_option("--json", cargs->json_out, "Also write the results as JSON to this file");
  compare->callback([cargs, &run] { run = [cargs] { return run_eval_compare(*cargs); }; });
}

}  // namespace g2p::cli
