// evaluate_segmentation on the shared assets: the ground truth scores itself
// perfectly, options fail before any work naming their flag, and the result
// is what `g2p eval seg --json` writes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "g2p/eval.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

// Two of the shared assets, 2 views at 128 px: seconds, not minutes.
SegmentationEvalOptions quick_options() {
  SegmentationEvalOptions o;
  o.assets = fs::path(test::labels_json_path()).parent_path().string();
  o.models = {"WaterBottle", "SheenChair"};
  o.views.num_views = 2;
  o.views.width = o.views.height = 128;
  return o;
}

TEST(SegmentationSet, TheOracleScoresPerfectly) {
  SegmentationEvalOptions o = quick_options();
  // The oracle reads the same labels.json (its key: the model file's name).
  o.segmenter = {"oracle", {{"labels", test::labels_json_path()}}};
  std::vector<std::string> seen;
  o.on_model = [&seen](const SegmentationModelEval& m) { seen.push_back(m.key); };
  Result<SegmentationEval> e = evaluate_segmentation(o);
  ASSERT_TRUE(e.ok()) << e.status().to_string();
  EXPECT_EQ(seen, o.models) << "on_model once per model, in order";
  ASSERT_EQ(e->models.size(), 2u);
  for (const SegmentationModelEval& m : e->models) {
    EXPECT_GT(m.pixels.total(), 0) << m.key;
    EXPECT_DOUBLE_EQ(m.pixels.accuracy(), 1.0) << m.key;
    EXPECT_DOUBLE_EQ(m.pixels.mean_iou(), 1.0) << m.key;
    EXPECT_GT(m.faces.total(), 0) << m.key;
    EXPECT_EQ(m.kind, "unknown");
    EXPECT_FALSE(m.refined);
  }
  EXPECT_DOUBLE_EQ(e->total.mean_iou(), 1.0);
  // Per face only faces no view saw can be wrong.
  EXPECT_GT(e->total_3d_per_model.mean_iou(), 0.9);
  // Every model weighs one.
  EXPECT_NEAR(e->total_3d_per_model.total(), 2.0, 1e-9);
  ASSERT_TRUE(e->interval.has_value());
  EXPECT_LE(e->interval->low, e->interval->high);

  const nlohmann::json j = nlohmann::json::parse(e->to_json());
  EXPECT_EQ(j["segmenter"], "oracle");
  EXPECT_EQ(j["vote"], "hard");
  EXPECT_EQ(j["refiner"], "none");
  EXPECT_EQ(j["views"], 2);
  EXPECT_EQ(j["resolution"], 128);
  EXPECT_DOUBLE_EQ(j["total"]["miou"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["models"]["SheenChair"]["2d"]["miou"].get<double>(), 1.0);
  EXPECT_FALSE(j["models"]["SheenChair"].contains("refine"));
  // The oracle's probabilities are one-hot and always right.
  EXPECT_DOUBLE_EQ(j["calibration"]["accuracy"].get<double>(), 1.0);
  EXPECT_NEAR(j["calibration"]["ece"].get<double>(), 0.0, 1e-12);
}

TEST(SegmentationSet, ABadOptionFailsBeforeAnyWorkNamingIt) {
  SegmentationEvalOptions o = quick_options();
  o.models = {"WaterBottle", "NoSuchModel"};
  o.on_model = [](const SegmentationModelEval& m) { ADD_FAILURE() << "scored " << m.key << " before the bad key"; };
  Result<SegmentationEval> e = evaluate_segmentation(o);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.status().code(), StatusCode::kNotFound);
  EXPECT_NE(e.status().message().find("'NoSuchModel'"), std::string::npos) << e.status().message();
  EXPECT_NE(e.status().message().find("--models"), std::string::npos) << e.status().message();
  EXPECT_NE(e.status().message().find("labels.json"), std::string::npos) << e.status().message();

  o = quick_options();
  o.object_from_names = true;  // with the identifier "none"
  SegmentationEvaluator names(o);
  Status s = names.prepare();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--object-from-names"), std::string::npos) << s.message();

  o = quick_options();
  o.refiner.settings["lambda"] = "2";  // with the refiner "none"
  s = SegmentationEvaluator(o).prepare();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--refine-set"), std::string::npos) << s.message();

  o = quick_options();
  o.refiner.name = "magic";
  s = SegmentationEvaluator(o).prepare();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("--refiner magic"), std::string::npos) << s.message();

  o = quick_options();
  o.kind_prior = 0.0;
  s = SegmentationEvaluator(o).prepare();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("--kind-prior"), std::string::npos) << s.message();

  o = quick_options();
  o.assets = test::scratch_dir("SegmentationSet.NoTruth");
  e = evaluate_segmentation(o);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find(o.assets + "/labels.json"), std::string::npos) << e.status().message();
}

// --split picks the keys of a labels.json elsewhere (--truth), in its order.
TEST(SegmentationSet, SplitAndTruthElsewhere) {
  const std::string dir = test::scratch_dir("SegmentationSet.Split");
  test::write_file(dir + "/labels.json", R"({"models": {
      "WaterBottle": {"split": "test", "labels": {"0": "Metal"}},
      "Avocado": {"split": "train", "labels": {"0": "Organic"}}}})");
  SegmentationEvalOptions o = quick_options();
  o.models.clear();
  o.truth = dir + "/labels.json";
  o.split = "test";
  o.segmenter = {"oracle", {{"labels", o.truth}}};
  Result<SegmentationEval> e = evaluate_segmentation(o);
  ASSERT_TRUE(e.ok()) << e.status().to_string();
  ASSERT_EQ(e->models.size(), 1u);
  EXPECT_EQ(e->models[0].key, "WaterBottle");
  EXPECT_DOUBLE_EQ(e->total.mean_iou(), 1.0);

  o.split = "validation";
  e = evaluate_segmentation(o);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("no model of split 'validation'"), std::string::npos) << e.status().message();
}

// The library's result is the tool's: the same options give `g2p eval seg
// --json` exactly (soft votes and a refiner on the weight-free `pbr`).
TEST(SegmentationSet, EqualsTheToolsJson) {
  const std::string tool = G2P_TEST_TOOL;
  if (!fs::is_regular_file(tool)) GTEST_SKIP() << "the g2p tool is not built (" << tool << ")";
  const std::string dir = test::scratch_dir("SegmentationSet.Tool");
  SegmentationEvalOptions o = quick_options();
  o.views.num_views = 3;
  o.views.width = o.views.height = 64;
  o.segmenter = {"pbr", {}};
  o.project.vote.mode = VoteMode::kSoft;
  o.refiner = {"smooth", {{"lambda", "4"}}};
  o.region_features = dir + "/library.csv";
  Result<SegmentationEval> e = evaluate_segmentation(o);
  ASSERT_TRUE(e.ok()) << e.status().to_string();
  const test::ToolRun r = test::run_tool(
      "eval seg --assets " + test::quote(o.assets) +
      " --models WaterBottle,SheenChair --views 3 --resolution 64 --segmenter pbr --soft --refiner smooth "
      "--refine-set lambda=4 --region-features " +
      test::quote(dir + "/tool.csv") + " --json " + test::quote(dir + "/tool.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(e->to_json() + "\n", test::read_file(dir + "/tool.json"));
  EXPECT_EQ(test::read_file(dir + "/library.csv"), test::read_file(dir + "/tool.csv"));
  const nlohmann::json j = nlohmann::json::parse(e->to_json());
  EXPECT_GT(j["models"]["SheenChair"]["refine"]["changed_faces"].get<int>(), 0) << j["models"]["SheenChair"].dump();
}

}  // namespace
}  // namespace g2p
