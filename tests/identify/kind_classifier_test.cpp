// The shipped kind classifier (libg2p/data/models/g2p-kinds.*, trained by
// tools/training/train_kinds.py; docs/kind-classifier.md): what its card
// promises, what it says of real models without their names, and a damaged
// card as the user meets it; summary.html's top three.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "g2p/identify.h"
#include "g2p/pipeline.h"
#include "support/test_data.h"

namespace g2p {
namespace {

const std::string kModels = test::source_path("libg2p/data/models");

Result<PipelineResult> identify_run(const std::string& identifier, const std::string& file) {
  PipelineOptions o;
  o.last_stage = Stage::kIdentify;
  o.anonymize_names = true;
  o.identifier = {identifier, {}};
  Pipeline p(o);
  return p.run_file(file);
}

// The kinds in the order the candidates list them.
std::vector<std::string> ranked(const Identification& id) {
  std::vector<std::string> kinds;
  for (const KindGuess& g : id.candidates) kinds.push_back(g.kind);
  return kinds;
}

// Sets an environment variable for the scope of a test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() { had_ ? (void)::setenv(name_, old_.c_str(), 1) : (void)::unsetenv(name_); }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

}  // namespace

TEST(KindClassifier, TheCardNamesKindsOfTheTableAndTheirTrainingCounts) {
  std::ifstream in(kModels + "/g2p-kinds.json");
  const nlohmann::json card = nlohmann::json::parse(in);
  EXPECT_EQ(card.at("format"), "g2p-kind-classifier-card");
  std::ifstream labels(kModels + "/" + card.at("labels").get<std::string>());
  std::vector<std::string> kinds;
  for (std::string line; std::getline(labels, line);) kinds.push_back(line);
  ASSERT_GE(kinds.size(), 50u);
  const ObjectTable& table = ObjectTable::shipped();
  std::set<std::string> seen;
  for (const std::string& k : kinds) {
    EXPECT_GE(table.find(k), 0) << "'" << k << "' is not a kind of the shipped table";
    EXPECT_TRUE(seen.insert(k).second) << k << " twice";
    // Every class had training models, as many as the card says (at least two).
    EXPECT_GE(card.at("kinds").value(k, 0), 2) << k;
  }
  EXPECT_EQ(card.at("kinds").size(), kinds.size());
  // A calibrated temperature, and views as the identifier renders them.
  EXPECT_GT(card.at("temperature").get<double>(), 0.2);
  EXPECT_LT(card.at("temperature").get<double>(), 10.0);
  EXPECT_EQ(card.at("input").at("shape").at(2), 224);
  EXPECT_TRUE(std::filesystem::is_regular_file(kModels + "/" + card.at("model").get<std::string>()));
  // The shape head: this build's cues, one output per class (with "other"), a weight in the join.
  const nlohmann::json& shape = card.at("shape");
  EXPECT_EQ(shape.at("cues").get<std::vector<std::string>>(), shape_cue_names());
  EXPECT_EQ(shape.at("layers").back().at("bias").size(), kinds.size() + 1);
  EXPECT_GT(shape.at("weight").get<double>(), 0.0);
  EXPECT_LT(shape.at("weight").get<double>(), 2.0);
}

TEST(KindClassifier, NamesABottleAndAChairFromTheirViewsAlone) {
  // Names removed: the views and the shape are all it has. Its confidences
  // are calibrated and low on their own; what it ranks first is what counts
  // here. SheenChair is a lounge chair with arms: chair or armchair.
  const std::vector<std::pair<std::string, std::set<std::string>>> cases = {{"WaterBottle", {"bottle"}},
                                                                            {"SheenChair", {"chair", "armchair"}}};
  for (const auto& [asset, kinds] : cases) {
    const std::string file = test::asset_path(asset);
    G2P_SKIP_WITHOUT(file);
    Result<PipelineResult> r = identify_run("classifier", file);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    const Identification& id = r->identification;
    EXPECT_TRUE(id.warnings.empty()) << id.warnings.front();
    ASSERT_FALSE(id.candidates.empty()) << asset;
    EXPECT_EQ(kinds.count(id.candidates.front().kind), 1u) << asset << ": " << id.candidates.front().kind;
    EXPECT_EQ(id.candidates.front().source, "classifier");
    EXPECT_NE(id.candidates.front().evidence.find("over 8 views"), std::string::npos);
    EXPECT_NE(id.candidates.front().evidence.find("with its shape"), std::string::npos)
        << id.candidates.front().evidence;
    // Calibrated confidences: each how often a top kind that sure was right,
    // ranked as the network ranked the kinds.
    for (std::size_t i = 0; i < id.candidates.size(); ++i) {
      EXPECT_GT(id.candidates[i].confidence, 0.0);
      EXPECT_LE(id.candidates[i].confidence, 1.0);
      if (i > 0) EXPECT_LE(id.candidates[i].confidence, id.candidates[i - 1].confidence);
    }
  }
}

TEST(KindClassifier, AutoJoinsItByDefaultAndADamagedCardIsAWarning) {
  const std::string file = test::generated_path("trellis_shell_chair.glb");
  G2P_SKIP_WITHOUT(file);
  Result<PipelineResult> plain = identify_run("auto", file);
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  bool voted = false;
  for (const KindGuess& g : plain->identification.candidates)
    voted = voted || g.source.find("classifier") != std::string::npos;
  EXPECT_TRUE(voted) << "the shipped classifier votes in auto";
  // summary.html names the kind and the next two, with their confidences.
  const Identification& first = plain->identification;
  ASSERT_GE(first.candidates.size(), 3u);
  PipelineOptions o;
  o.anonymize_names = true;
  const std::string html = summary_html(*plain, o);
  EXPECT_NE(html.find("What it is: <b>" + first.kind() + "</b>"), std::string::npos);
  const std::size_t perhaps = html.find("; else perhaps " + first.candidates[1].kind + " (");
  EXPECT_NE(perhaps, std::string::npos);
  EXPECT_NE(html.find(", " + first.candidates[2].kind + " (", perhaps), std::string::npos);
  // A card that is not JSON, in the first folder searched: auto says which
  // file and goes on with the names and the detector.
  const std::string dir = test::scratch_dir("KindClassifierDamagedCard");
  std::ofstream(dir + "/g2p-kinds.json") << "{ not json";
  ScopedEnv env("G2P_MODEL_DIR", dir);
  Result<PipelineResult> damaged = identify_run("auto", file);
  ASSERT_TRUE(damaged.ok()) << damaged.status().to_string();
  const Identification& id = damaged->identification;
  ASSERT_FALSE(id.warnings.empty());
  EXPECT_NE(id.warnings.front().find("g2p-kinds.json"), std::string::npos) << id.warnings.front();
  EXPECT_NE(id.warnings.front().find("not valid JSON"), std::string::npos) << id.warnings.front();
  for (const KindGuess& g : id.candidates) EXPECT_EQ(g.source.find("classifier"), std::string::npos);
  EXPECT_FALSE(ranked(id).empty()) << "the detector still answers";
}

TEST(KindClassifier, AShapeHeadOfOtherCuesIsAWarningNamingTheField) {
  const std::string file = test::asset_path("WaterBottle");
  G2P_SKIP_WITHOUT(file);
  // The shipped card, its shape head made for cues this build does not have.
  std::ifstream in(kModels + "/g2p-kinds.json");
  nlohmann::json card = nlohmann::json::parse(in);
  card["shape"]["cues"][0] = "roundness";
  const std::string dir = test::scratch_dir("KindClassifierOtherCues");
  for (const char* f : {"model", "labels"}) {
    const std::string name = card.at(f).get<std::string>();
    std::filesystem::remove(dir + "/" + name);
    std::filesystem::create_symlink(kModels + "/" + name, dir + "/" + name);
  }
  std::ofstream(dir + "/g2p-kinds.json") << card.dump();
  ScopedEnv env("G2P_MODEL_DIR", dir);
  Result<PipelineResult> r = identify_run("classifier", file);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const Identification& id = r->identification;
  ASSERT_FALSE(id.warnings.empty());
  EXPECT_NE(id.warnings.front().find("g2p-kinds.json: shape.cues"), std::string::npos) << id.warnings.front();
  EXPECT_TRUE(id.candidates.empty());
}

}  // namespace g2p
