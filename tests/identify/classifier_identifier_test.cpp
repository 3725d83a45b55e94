// The "classifier" identifier: an ImageNet classifier the user supplies
// (../shared/models/imagenet-mobilenet-v2, for tests only), its classes mapped
// to kinds through WordNet, alone and voting in `auto`; the shipped kind
// classifier is tested in kind_classifier_test.cpp.
#include <gtest/gtest.h>

#include <fstream>

#include "g2p/identify.h"
#include "g2p/pipeline.h"
#include "support/test_data.h"

namespace g2p {
namespace {

const std::string kModel = test::shared_model_path("imagenet-mobilenet-v2/mobilenet_v2_1.0_224.onnx");
const std::string kWnids = test::shared_model_path("imagenet-mobilenet-v2/imagenet_wnids.json");  // 1000 ids
const std::string kWords = test::shared_model_path("imagenet-mobilenet-v2/imagenet_labels.txt");  // 1001 lines
const std::string kChair = test::generated_path("trellis_shell_chair.glb");

// The pipeline up to identify, names removed: what the views alone say.
Result<PipelineResult> identify_run(const std::string& identifier, const BackendSettings& settings,
                                    const std::string& file) {
  PipelineOptions o;
  o.last_stage = Stage::kIdentify;
  o.views.width = o.views.height = 256;
  o.anonymize_names = true;
  o.identifier = {identifier, settings};
  Pipeline p(o);
  return p.run_file(file);
}

double confidence_of(const Identification& id, const std::string& kind) {
  for (const KindGuess& g : id.candidates)
    if (g.kind == kind) return g.confidence;
  return 0.0;
}

TEST(ClassifierIdentifier, AnImageNetNetworkRecognisesAGeneratedChairWithoutNames) {
  G2P_SKIP_WITHOUT(kModel);
  G2P_SKIP_WITHOUT(kChair);
  // Its 1000 classes as WordNet ids; the network's 1001st score, first, is background.
  Result<PipelineResult> r = identify_run("classifier", {{"model", kModel}, {"labels", kWnids}}, kChair);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const Identification& id = r->identification;
  EXPECT_TRUE(id.warnings.empty()) << id.warnings.front();
  ASSERT_TRUE(id.known());
  EXPECT_EQ(id.kind(), "chair");  // ImageNet's folding, rocking and barber chairs are WordNet chairs
  EXPECT_EQ(id.source(), "classifier");
  EXPECT_GE(id.confidence(), 0.4);
  EXPECT_LE(id.confidence(), 1.0);
  EXPECT_NE(id.candidates.front().evidence.find("over 8 views"), std::string::npos) << id.candidates.front().evidence;
  // The same classes named in words (ImageNet's synonyms, "background" first)
  // map to the same kinds: the table's terms are WordNet's lemmas under each kind.
  Result<PipelineResult> words = identify_run("classifier", {{"model", kModel}, {"labels", kWords}}, kChair);
  ASSERT_TRUE(words.ok()) << words.status().to_string();
  EXPECT_EQ(words->identification.kind(), "chair");
  EXPECT_NEAR(words->identification.confidence(), id.confidence(), 0.02);
  EXPECT_NE(words->identification.candidates.front().evidence.find("chair'"), std::string::npos)
      << words->identification.candidates.front().evidence;
}

TEST(ClassifierIdentifier, AutoJoinsTheUsersNetworkWithTheDetector) {
  G2P_SKIP_WITHOUT(kModel);
  G2P_SKIP_WITHOUT(kChair);
  Result<PipelineResult> plain = identify_run("auto", {{"classifier", "off"}}, kChair);
  Result<PipelineResult> with = identify_run("auto", {{"model", kModel}, {"labels", kWnids}}, kChair);
  ASSERT_TRUE(plain.ok() && with.ok());
  for (const KindGuess& g : plain->identification.candidates)
    EXPECT_EQ(g.source.find("classifier"), std::string::npos) << g.kind << " from " << g.source;
  // The detector alone does not see this chair (it reads it as a toilet);
  // with the classifier the chair leads.
  EXPECT_GT(confidence_of(with->identification, "chair"), confidence_of(plain->identification, "chair") + 0.3);
  EXPECT_EQ(with->identification.kind(), "chair");
  EXPECT_NE(with->identification.source().find("classifier"), std::string::npos);
}

TEST(ClassifierIdentifier, LabelsThatDoNotFitTheNetworkAreNamedAndAutoGoesOnWithout) {
  G2P_SKIP_WITHOUT(kModel);
  const std::string dir = test::scratch_dir("ClassifierIdentifier.Labels");
  const std::string short_labels = dir + "/short.txt";
  {
    std::ofstream f(short_labels);
    for (int i = 0; i < 998; ++i) f << "class " << i << "\n";
  }
  // Alone: a warning naming both counts and the flags, and no kind.
  Result<PipelineResult> alone =
      identify_run("classifier", {{"model", kModel}, {"labels", short_labels}}, test::asset_path("WaterBottle"));
  ASSERT_TRUE(alone.ok()) << alone.status().to_string();
  EXPECT_FALSE(alone->identification.known());
  ASSERT_FALSE(alone->identification.warnings.empty());
  const std::string& w = alone->identification.warnings.front();
  EXPECT_NE(w.find("1001 scores"), std::string::npos) << w;
  EXPECT_NE(w.find("labels=" + short_labels), std::string::npos) << w;
  EXPECT_NE(w.find("998 classes"), std::string::npos) << w;
  // In auto the names still identify the bottle, the warning says why the classifier did not.
  Result<PipelineResult> with_names = [&] {
    PipelineOptions o;
    o.last_stage = Stage::kIdentify;
    o.views.width = o.views.height = 128;
    o.identifier = {"auto", {{"model", kModel}, {"labels", short_labels}}};
    return Pipeline(o).run_file(test::asset_path("WaterBottle"));
  }();
  ASSERT_TRUE(with_names.ok()) << with_names.status().to_string();
  EXPECT_EQ(with_names->identification.kind(), "bottle");
  bool warned = false;
  for (const std::string& x : with_names->warnings) warned |= x.find("998 classes") != std::string::npos;
  EXPECT_TRUE(warned);
  // A blank class in the middle of the list would shift every class after it: refused.
  const std::string blank = dir + "/blank.txt";
  test::write_file(blank, "n03376595 folding chair\n\nn04099969 rocking chair\n");
  Result<std::unique_ptr<Identifier>> c = make_identifier("classifier", {{"model", kModel}, {"labels", blank}});
  ASSERT_TRUE(c.ok());
  Result<PipelineResult> r =
      identify_run("classifier", {{"model", kModel}, {"labels", blank}}, test::asset_path("SheenChair"));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_FALSE(r->identification.warnings.empty());
  EXPECT_NE(r->identification.warnings.front().find("class 2 is blank"), std::string::npos)
      << r->identification.warnings.front();
}

TEST(ClassifierIdentifier, SettingsAreCheckedBeforeAnyWork) {
  // A model without labels (or labels without a model) cannot be read.
  EXPECT_EQ(make_identifier("classifier", {{"labels", test::labels_json_path()}}).status().code(),
            StatusCode::kInvalidArgument);
  // Files must exist; the input side and the probability have ranges.
  EXPECT_FALSE(make_identifier("classifier", {{"model", "/nonexistent/net.onnx"}}).ok());
  EXPECT_FALSE(make_identifier("classifier", {{"size", "8"}}).ok());
  EXPECT_FALSE(make_identifier("classifier", {{"min_probability", "1.5"}}).ok());
  EXPECT_FALSE(make_identifier("classifier", {{"normalization", "caffe"}}).ok());
  // Without views it says so and names nothing.
  Result<std::unique_ptr<Identifier>> shipped = make_identifier("classifier");
  ASSERT_TRUE(shipped.ok());
  IdentifyInput in;
  Result<Identification> id = (*shipped)->identify(in);
  ASSERT_TRUE(id.ok());
  EXPECT_FALSE(id->known());
  ASSERT_FALSE(id->notes.empty());
  EXPECT_NE(id->notes.front().find("no rendered views"), std::string::npos);
  // `auto` takes the classifier's settings beside the detector's, and can
  // leave either out.
  EXPECT_TRUE(make_identifier("auto", {{"min_probability", "0.2"}, {"min_score", "0.4"}}).ok());
  EXPECT_TRUE(make_identifier("auto", {{"classifier", "off"}, {"detector", "off"}}).ok());
}

}  // namespace
}  // namespace g2p
