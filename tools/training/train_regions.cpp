// g2p_train_regions: trains the region classifier (regions.h) on the CSV rows
// `g2p eval seg --region-features` writes, and writes its trees and model
// card. tools/training/train_regions.sh is the committed recipe of the
// shipped classifier (docs/training.md#the-region-classifier).
//
//   g2p_train_regions TRAIN.csv [MORE.csv ...] -o DIR [--check VAL.csv]
//
// A row trains when its region has a true class for most of its labelled
// area (--min-purity) and most of its area is labelled (--min-labelled). Its
// weight is the region's share of its model's surface, so every model weighs
// about the same, as in the per-face mIoU the classifier is judged by.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "core/csv.h"
#include "g2p/materials.h"
#include "g2p/regions.h"

namespace {

struct Rows {
  std::vector<float> features;
  std::vector<int> labels;
  std::vector<float> weights;
  std::set<std::string> models;
};

// Reads the rows of `path` that train; false with a message on bad input.
bool read_rows(const std::string& path, const g2p::MaterialTable& table, double min_purity, double min_labelled,
               Rows& rows, std::string& error) {
  std::ifstream in(path);
  if (!in) return error = path + ": cannot be read", false;
  std::string line;
  if (!std::getline(in, line)) return error = path + ": empty", false;
  const std::vector<std::string> header = g2p::detail::csv_fields(line);
  const std::vector<std::string> names = g2p::region_feature_names(table);
  const std::size_t first = 7;  // model,region,faces,area_share,truth,truth_share,labelled_share
  if (header.size() != first + names.size() || !std::equal(names.begin(), names.end(), header.begin() + first))
    return error = path + ": not the region features this libg2p writes (g2p eval seg --region-features)", false;
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    const std::vector<std::string> cells = g2p::detail::csv_fields(line);
    if (cells.size() != header.size())
      return error = path + ":" + std::to_string(number) + ": " + std::to_string(cells.size()) + " cells, expected " +
                     std::to_string(header.size()),
             false;
    if (cells[4].empty()) continue;
    const int label = table.find(cells[4]);
    if (label < 0) return error = path + ":" + std::to_string(number) + ": unknown class '" + cells[4] + "'", false;
    try {
      if (std::stod(cells[5]) < min_purity || std::stod(cells[6]) < min_labelled) continue;
      rows.weights.push_back(static_cast<float>(std::stod(cells[3])));
      for (std::size_t i = first; i < cells.size(); ++i)
        rows.features.push_back(static_cast<float>(std::stod(cells[i])));
    } catch (const std::exception&) {
      return error = path + ":" + std::to_string(number) + ": a value is not a number", false;
    }
    rows.labels.push_back(label);
    rows.models.insert(cells[0]);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Train the region classifier on g2p eval seg --region-features CSV files"};
  std::vector<std::string> inputs;
  std::string out_dir, check;
  double min_purity = 0.6, min_labelled = 0.5;
  g2p::RegionTrainOptions options;
  app.add_option("csv", inputs, "Training rows (g2p eval seg --region-features)")->required();
  app.add_option("-o,--out", out_dir, "Folder for g2p-regions.json and g2p-regions.yml.gz")->required();
  app.add_option("--check", check, "Score the trained classifier on these rows (validation)");
  app.add_option("--min-purity", min_purity, "Train on a region only when its true class has this share (0.6)");
  app.add_option("--min-labelled", min_labelled, "...and this share of its area is labelled (0.5)");
  bool balance = false;
  app.add_flag("--balance", balance,
               "Weigh each class's regions so that every class has the same total weight (per-class IoU counts every "
               "class the same)");
  app.add_option("--trees", options.trees, "Random trees (200)")->check(CLI::Range(1, 5000));
  app.add_option("--depth", options.max_depth, "Tree depth (16)")->check(CLI::Range(1, 64));
  app.add_option("--min-samples", options.min_samples, "Fewest samples a node splits (4)")->check(CLI::Range(1, 1000));
  CLI11_PARSE(app, argc, argv);

  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  Rows train;
  std::string error;
  for (const std::string& path : inputs)
    if (!read_rows(path, table, min_purity, min_labelled, train, error)) {
      std::cerr << "g2p_train_regions: error: " << error << "\n";
      return 1;
    }
  if (train.labels.empty()) {
    std::cerr << "g2p_train_regions: error: no row with a true class in the " << inputs.size() << " file(s)\n";
    return 1;
  }
  const int width = static_cast<int>(g2p::region_feature_names(table).size());
  if (balance) {
    std::vector<double> by_class(static_cast<std::size_t>(table.size()), 0.0);
    double all = 0.0;
    for (std::size_t i = 0; i < train.labels.size(); ++i)
      by_class[train.labels[i]] += train.weights[i], all += train.weights[i];
    int present = 0;
    for (const double w : by_class) present += w > 0.0;
    for (std::size_t i = 0; i < train.labels.size(); ++i)
      if (by_class[train.labels[i]] > 0.0)  // a class whose rows all weigh 0 stays at 0
        train.weights[i] = static_cast<float>(train.weights[i] * all / (present * by_class[train.labels[i]]));
  }
  const std::string trees_name = "g2p-regions.yml.gz";
  const std::string trees_path = out_dir + "/" + trees_name;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << "g2p_train_regions: error: -o " << out_dir << ": " << ec.message() << "\n";
    return 1;
  }
  if (g2p::Status s = g2p::train_region_classifier(train.features, train.labels, train.weights, width, table.size(),
                                                   options, trees_path);
      !s.ok()) {
    std::cerr << "g2p_train_regions: error: " << s.to_string() << "\n";
    return 1;
  }
  std::map<std::string, int> per_class;
  for (const int l : train.labels) ++per_class[table[l].name];
  nlohmann::json classes = nlohmann::json::array(), features = g2p::region_feature_names(table);
  nlohmann::json files = nlohmann::json::array();
  for (const std::string& path : inputs) files.push_back(std::filesystem::path(path).filename().string());
  for (const g2p::MaterialClass& c : table.classes()) classes.push_back(c.name);
  nlohmann::json card = {
      {"format", "g2p-region-classifier"},
      {"version", 1},
      {"classes", classes},
      {"features", features},
      {"trees", trees_name},
      {"learner",
       {{"kind", "OpenCV random trees (cv::ml::RTrees)"},
        {"trees", options.trees},
        {"max_depth", options.max_depth},
        {"min_samples", options.min_samples},
        {"features_per_split", "square root of the feature count"}}},
      {"training",
       {{"files", files},
        {"regions", train.labels.size()},
        {"models", train.models.size()},
        {"regions_per_class", per_class},
        {"min_purity", min_purity},
        {"min_labelled", min_labelled},
        {"weight", balance ? "the region's share of its model's surface, times its class's inverse share of all "
                             "weight (classes balanced)"
                           : "the region's share of its model's surface"}}},
  };
  const std::string card_path = out_dir + "/g2p-regions.json";
  g2p::Result<g2p::RegionClassifier> classifier = g2p::Status::NotFound("");
  if (!(std::ofstream(card_path) << card.dump(2) << "\n")) {
    std::cerr << "g2p_train_regions: error: " << card_path << " cannot be written\n";
    return 1;
  }
  classifier = g2p::RegionClassifier::load(card_path, table);
  if (!classifier.ok()) {
    std::cerr << "g2p_train_regions: error: the written classifier does not load: " << classifier.status().to_string()
              << "\n";
    return 1;
  }
  std::printf("trained on %zu regions of %zu models: %s\n", train.labels.size(), train.models.size(),
              card_path.c_str());
  if (!check.empty()) {
    Rows val;
    if (!read_rows(check, table, 0.0, 0.0, val, error)) {
      std::cerr << "g2p_train_regions: error: " << error << "\n";
      return 1;
    }
    g2p::Result<std::vector<float>> p = classifier->predict(val.features, static_cast<int>(val.labels.size()));
    if (!p.ok()) {
      std::cerr << "g2p_train_regions: error: " << p.status().to_string() << "\n";
      return 1;
    }
    if (val.labels.empty()) {
      std::cerr << "g2p_train_regions: error: --check " << check << ": no row with a true class\n";
      return 1;
    }
    // Area-weighted accuracy of the classifier and of the region's own votes.
    double right = 0, voted_right = 0, total = 0;
    for (std::size_t r = 0; r < val.labels.size(); ++r) {
      const float* q = p->data() + r * table.size();
      const float* v = val.features.data() + r * width;
      int best = 0, voted = 0;
      for (int c = 1; c < table.size(); ++c) {
        if (q[c] > q[best]) best = c;
        if (v[c] > v[voted]) voted = c;
      }
      total += val.weights[r];
      right += best == val.labels[r] ? val.weights[r] : 0.f;
      voted_right += voted == val.labels[r] ? val.weights[r] : 0.f;
    }
    card["validation"] = {{"file", std::filesystem::path(check).filename().string()},
                          {"regions", val.labels.size()},
                          {"models", val.models.size()},
                          {"area_weighted_accuracy", right / total},
                          {"votes_alone_accuracy", voted_right / total}};
    if (!(std::ofstream(card_path) << card.dump(2) << "\n")) {
      std::cerr << "g2p_train_regions: error: " << card_path << " cannot be written\n";
      return 1;
    }
    std::printf(
        "check %s: %zu regions of %zu models; area-weighted accuracy %.2f %% (the regions' votes alone %.2f %%)\n",
        check.c_str(), val.labels.size(), val.models.size(), 100.0 * right / total, 100.0 * voted_right / total);
  }
  return 0;
}
