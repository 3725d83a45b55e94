#include <gtest/gtest.h>

#include "g2p/segment.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(OracleSegmenter, LabelsEveryPixelWithItsMaterialsGroundTruth) {
  Result<Model> model = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(model.ok());
  const std::vector<View> views = test::render(*model, 3, 64);
  const MaterialTable& table = MaterialTable::paper_default();
  // The key defaults to the model file's stem ("SheenChair").
  auto oracle = std::move(*make_segmenter("oracle", {{"labels", test::labels_json_path()}}));
  ASSERT_TRUE(oracle->set_model(*model, table).ok());
  const int by_material[] = {table.find("Fabric"), table.find("Wood"), table.find("Metal"), kUnknownLabel};
  int labelled = 0;
  for (const View& v : views) {
    Result<LabelMap> map = oracle->segment(v);
    ASSERT_TRUE(map.ok());
    for (std::size_t i = 0; i < v.face_id.size(); ++i) {
      const int f = v.face_id.data()[i];
      const int expected = f < 0 ? kUnknownLabel : by_material[model->mesh.face_source[f].material];
      ASSERT_EQ(map->labels.data()[i], expected);
      labelled += expected >= 0;
    }
  }
  EXPECT_GT(labelled, 1000);
}

TEST(OracleSegmenter, AnonymizedNamesKeepTheDefaultKey) {
  Result<Model> model = load_model(test::asset_path("Avocado"));
  ASSERT_TRUE(model.ok());
  anonymize_names(*model);
  EXPECT_EQ(model->materials[0].name, "material_0");
  auto oracle = std::move(*make_segmenter("oracle", {{"labels", test::labels_json_path()}}));
  EXPECT_TRUE(oracle->set_model(*model, MaterialTable::paper_default()).ok());  // key "Avocado" from the path
}

TEST(OracleSegmenter, LabelFileErrors) {
  const MaterialTable& table = MaterialTable::paper_default();
  EXPECT_EQ(material_labels_from_json(R"({"models": {"A": {"labels": {}}}})", "B", table, 1).status().code(),
            StatusCode::kNotFound);
  EXPECT_NE(material_labels_from_json(R"({"labels": {"0": "Unobtainium"}})", "", table, 1)
                .status()
                .message()
                .find("'Unobtainium' is not in the material table"),
            std::string::npos);
  EXPECT_EQ(material_labels_from_json(R"({"labels": {"x": "Wood"}})", "", table, 1).status().code(),
            StatusCode::kParseError);
  Result<std::vector<int>> ok = material_labels_from_json(R"({"labels": {"0": "Wood", "1": "ignore"}})", "", table, 3);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok, (std::vector<int>{table.find("Wood"), kUnknownLabel, kUnknownLabel}));

  Model empty_model;
  Result<std::unique_ptr<Segmenter>> no_file = make_segmenter("oracle");  // refused when made
  ASSERT_FALSE(no_file.ok());
  EXPECT_EQ(no_file.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(no_file.status().message().find("labels=FILE.json"), std::string::npos) << no_file.status().message();
  auto missing = std::move(*make_segmenter("oracle", {{"labels", "/nonexistent/labels.json"}}));
  EXPECT_EQ(missing->set_model(empty_model, table).code(), StatusCode::kNotFound);
  EXPECT_EQ(make_segmenter("oracle", {{"label", "x"}}).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p
