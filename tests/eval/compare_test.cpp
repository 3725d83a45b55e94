// compare_segmentation_runs: two `g2p eval seg --json` documents paired by
// model, the bootstrap of their mIoU difference, the text and JSON
// `g2p eval compare` prints, and the runs it refuses.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "g2p/eval.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// A model whose faces of classes 0 and 5 weigh `weight` each; `wrong` of
// class 5's weight is taken for class 0.
ConfusionMatrix faces(double weight, double wrong) {
  ConfusionMatrix m(static_cast<int>(MaterialTable::paper_default().size()));
  m.add(0, 0, weight);
  m.add(5, 5, weight - wrong);
  m.add(5, 0, wrong);
  return m;
}

// A run over three models (in other units: each weighs the same all the same)
// whose class 5 is confused on `wrong` of its weight.
SegmentationEval run(const std::string& segmenter, double wrong) {
  SegmentationEval e;
  e.options.segmenter = {segmenter, {}};
  const double scale[] = {1.0, 10.0, 1000.0};
  const char* keys[] = {"Chair", "Bottle", "Lamp"};
  for (int i = 0; i < 3; ++i) {
    SegmentationModelEval m;
    m.key = keys[i];
    m.pixels = ConfusionMatrix(static_cast<int>(MaterialTable::paper_default().size()));
    m.faces = faces(scale[i], wrong * scale[i] * (i + 1) / 3.0);
    e.models.push_back(std::move(m));
  }
  return e;
}

std::vector<ConfusionMatrix> matrices(const SegmentationEval& e) {
  std::vector<ConfusionMatrix> out;
  for (const SegmentationModelEval& m : e.models) out.push_back(m.faces);
  return out;
}

TEST(CompareSegmentationRuns, PairsTheModelsAndPrintsTheVerdict) {
  const SegmentationEval a = run("pbr", 0.6);
  SegmentationEval b = run("learned", 0.1);
  b.options.refiner = {"smooth", {}};
  b.options.project.vote.mode = VoteMode::kSoft;
  b.options.views.num_views = 6;
  std::swap(b.models[0], b.models[2]);  // paired by key, not by order
  SegmentationComparisonOptions options;
  options.resamples = 500;
  Result<SegmentationComparison> c = compare_segmentation_runs(a.to_json(), "a.json", b.to_json(), "b.json", options);
  ASSERT_TRUE(c.ok()) << c.status().to_string();

  // The same figures as the bootstrap itself over the paired matrices.
  std::vector<ConfusionMatrix> right = matrices(b);
  std::swap(right[0], right[2]);
  Result<MeanIouDifference> d = bootstrap_mean_iou_difference(matrices(a), right, 0.95, 500, options.seed);
  ASSERT_TRUE(d.ok()) << d.status().to_string();
  EXPECT_DOUBLE_EQ(c->difference.miou_a, d->miou_a);
  EXPECT_DOUBLE_EQ(c->difference.miou_b, d->miou_b);
  EXPECT_DOUBLE_EQ(c->difference.low, d->low);
  EXPECT_DOUBLE_EQ(c->difference.high, d->high);
  EXPECT_EQ(c->difference.models, 3);
  EXPECT_GT(c->difference.low, 0.0);  // B confuses less on every model

  EXPECT_EQ(c->a, "a.json");
  EXPECT_EQ(c->label_a, "pbr, hard votes");
  EXPECT_EQ(c->label_b, "learned + smooth, soft votes");
  EXPECT_EQ(c->differing_conditions, "vote (\"hard\" / \"soft\"), views (11 / 6)");
  const MaterialTable table = MaterialTable::paper_default();
  ASSERT_EQ(c->per_class.size(), 2u);
  EXPECT_EQ(c->per_class[0].name, table[0].name);
  EXPECT_EQ(c->per_class[1].name, table[5].name);
  EXPECT_LT(c->per_class[1].a, c->per_class[1].b);

  const std::string text = c->to_text();
  EXPECT_EQ(text.rfind("A: a.json (pbr, hard votes): mIoU ", 0), 0u) << text;
  EXPECT_NE(text.find("(paired bootstrap, 500 resamples of 3 models)\nB is better: the interval lies above zero\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("| class | A | B | B - A |\n|---|---:|---:|---:|\n| " + table[0].name + " | "), std::string::npos)
      << text;
  EXPECT_EQ(text.back(), '\n');

  const nlohmann::json j = nlohmann::json::parse(c->to_json());
  EXPECT_EQ(j["b"], "b.json");
  EXPECT_DOUBLE_EQ(j["difference"].get<double>(), d->difference);
  EXPECT_EQ(j["resamples"], 500);
  EXPECT_EQ(j["models"], 3);
  EXPECT_DOUBLE_EQ(j["iou_per_class"][table[5].name]["b"].get<double>(), c->per_class[1].b);
}

TEST(CompareSegmentationRuns, ARunAgainstItselfIsNotResolved) {
  const std::string a = run("pbr", 0.5).to_json();
  Result<SegmentationComparison> c = compare_segmentation_runs(a, "a", a, "a");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  EXPECT_EQ(c->difference.difference, 0.0);
  EXPECT_EQ(c->differing_conditions, "");
  EXPECT_NE(c->to_text().find("B - A: +0.00 points, 95 % interval +0.00 to +0.00 (paired bootstrap, 2000 resamples"),
            std::string::npos);
  EXPECT_NE(c->to_text().find("not resolved: the interval includes zero"), std::string::npos);
}

TEST(CompareSegmentationRuns, RefusesWhatCannotBePaired) {
  const SegmentationEval a = run("pbr", 0.5);
  SegmentationEval fewer = a;
  fewer.models.pop_back();
  Result<SegmentationComparison> c = compare_segmentation_runs(a.to_json(), "a", fewer.to_json(), "f");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(c.status().message(),
            "a and f score other models (3 and 2 models; only in the first: Lamp); a paired comparison needs the same "
            "models");

  SegmentationEval relabelled = a;
  relabelled.models[1].faces = faces(20.0, 0.0);  // twice the truth of Bottle
  c = compare_segmentation_runs(a.to_json(), "a", relabelled.to_json(), "r");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("other ground truth on the two sides"), std::string::npos)
      << c.status().message();

  c = compare_segmentation_runs(R"({"segmenter": "pbr"})", "broken.json", a.to_json(), "a");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), "broken.json: not a g2p eval seg --json file (no \"models\" object)");
  c = compare_segmentation_runs(a.to_json(), "a", R"({"models": {}})", "empty.json");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), "empty.json: scores no model");
  c = compare_segmentation_runs(a.to_json(), "a", R"({"models": {"Chair": {"2d": {}}}})", "no3d.json");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), "no3d.json: model Chair has no \"3d\" matrix");
}

TEST(CompareSegmentationFiles, ReadsTwoEvalSegFiles) {
  const std::string dir = test::scratch_dir("CompareSegmentationFiles");
  const SegmentationEval a = run("pbr", 0.5), b = run("learned", 0.2);
  test::write_file(dir + "/a.json", a.to_json() + "\n");
  test::write_file(dir + "/b.json", b.to_json() + "\n");
  Result<SegmentationComparison> files = compare_segmentation_files(dir + "/a.json", dir + "/b.json");
  ASSERT_TRUE(files.ok()) << files.status().to_string();
  Result<SegmentationComparison> texts =
      compare_segmentation_runs(a.to_json(), dir + "/a.json", b.to_json(), dir + "/b.json");
  ASSERT_TRUE(texts.ok()) << texts.status().to_string();
  EXPECT_EQ(files->to_text(), texts->to_text());
  EXPECT_EQ(files->to_json(), texts->to_json());

  Result<SegmentationComparison> missing = compare_segmentation_files(dir + "/missing.json", dir + "/b.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(missing.status().message(), dir + "/missing.json: cannot open");
}

}  // namespace
}  // namespace g2p
