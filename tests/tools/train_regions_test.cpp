// g2p_train_regions (tools/training/train_regions.cpp) on the rows that
// `g2p eval seg --region-features` writes for the shared assets: the trained
// card loads, and the CSV reader takes RFC 4180 quoting and Windows line
// ends and names the line of a bad row.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "g2p/materials.h"
#include "g2p/regions.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;
using test::quote;

test::ToolRun train(const std::string& args) { return test::run_command(quote(G2P_TEST_TRAIN_REGIONS) + " " + args); }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(TrainRegions, TrainsOnTheRowsEvalSegWrites) {
  const std::string dir = test::scratch_dir("TrainRegions");
  const std::string assets = fs::path(test::labels_json_path()).parent_path().string();
  test::ToolRun r =
      test::run_tool("eval seg --assets " + quote(assets) +
                     " --segmenter pbr --views 3 --resolution 96 --region-features " + quote(dir + "/rows.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::vector<std::string> lines = lines_of(test::read_file(dir + "/rows.csv"));
  ASSERT_GT(lines.size(), 6u);
  EXPECT_EQ(lines[0].rfind("model,region,faces,area_share,truth,truth_share,labelled_share,", 0), 0u) << lines[0];
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(lines[i].front(), '"') << "keys are quoted: " << lines[i];

  // The same rows with Windows line ends, and two models renamed to keys that
  // differ only by a quote: a"b (written "a""b") and ab. A reader that drops
  // the doubled quote would count them as one model.
  std::string windows;
  std::string renamed[2];
  for (std::size_t i = 1; i < lines.size() && renamed[1].empty(); ++i) {
    // A model with a row that trains: a true class, 60 % of the region, half of it labelled.
    std::vector<std::string> cells;
    std::istringstream row(lines[i]);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (cells.size() < 7 || cells[4].empty() || std::stod(cells[5]) < 0.6 || std::stod(cells[6]) < 0.5) continue;
    const std::string& key = cells[0];
    if (renamed[0].empty())
      renamed[0] = key;
    else if (key != renamed[0])
      renamed[1] = key;
  }
  ASSERT_FALSE(renamed[1].empty()) << "two models with regions";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    std::string line = lines[i];
    const std::string key = line.substr(0, line.find(','));
    if (i > 0 && key == renamed[0]) line = "\"odd, a\"\"b\"" + line.substr(key.size());
    if (i > 0 && key == renamed[1]) line = "\"odd, ab\"" + line.substr(key.size());
    windows += line + "\r\n";
  }
  test::write_file(dir + "/windows.csv", windows);
  r = train(quote(dir + "/windows.csv") + " -o " + quote(dir + "/windows") + " --trees 5 --check " +
            quote(dir + "/rows.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  Result<RegionClassifier> classifier =
      RegionClassifier::load(dir + "/windows/g2p-regions.json", MaterialTable::paper_default());
  ASSERT_TRUE(classifier.ok()) << classifier.status().to_string();
  EXPECT_EQ(classifier->num_features(), static_cast<int>(region_feature_names(MaterialTable::paper_default()).size()));
  // ...and it read the same regions of as many models as the file as written.
  r = train(quote(dir + "/rows.csv") + " -o " + quote(dir + "/plain") + " --trees 5");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json plain = nlohmann::json::parse(test::read_file(dir + "/plain/g2p-regions.json"));
  const nlohmann::json odd = nlohmann::json::parse(test::read_file(dir + "/windows/g2p-regions.json"));
  EXPECT_GT(plain["training"]["regions"].get<int>(), 5);
  EXPECT_EQ(odd["training"]["regions"], plain["training"]["regions"]);
  EXPECT_EQ(odd["training"]["models"], plain["training"]["models"]) << "the two renamed keys are two models";
  // --check scored the classifier on rows.csv, its own training regions (by
  // other names): it must beat the regions' own votes there, and a classifier
  // that answered one class for everything would not (measured: 0.99 against
  // 0.88).
  const nlohmann::json& check = odd["validation"];
  EXPECT_GE(check["regions"].get<int>(), plain["training"]["regions"].get<int>());
  EXPECT_GT(check["area_weighted_accuracy"].get<double>(), check["votes_alone_accuracy"].get<double>() + 0.05)
      << check.dump();
  EXPECT_GT(check["area_weighted_accuracy"].get<double>(), 0.9) << check.dump();

  // A row cut short: refused, naming the file and the line.
  std::string cut = lines[0] + "\n" + lines[1] + "\n" + lines[2].substr(0, lines[2].rfind(',')) + "\n";
  test::write_file(dir + "/cut.csv", cut);
  r = train(quote(dir + "/cut.csv") + " -o " + quote(dir + "/cut"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("cut.csv:3:"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace g2p
