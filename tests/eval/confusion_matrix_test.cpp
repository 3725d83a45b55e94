// ConfusionMatrix against hand-computed values.
#include "g2p/eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace g2p {
namespace {

// Three classes. Truth/prediction pairs (count):
//   0->0 (5), 0->1 (1), 1->1 (3), 1->0 (2), 1->unknown (1), void->2 (4, ignored), 2 never occurs.
ConfusionMatrix fixture() {
  ConfusionMatrix m(3);
  for (int i = 0; i < 5; ++i) m.add(0, 0);
  m.add(0, 1);
  for (int i = 0; i < 3; ++i) m.add(1, 1);
  m.add(1, 0, 2.0);
  m.add(1, kUnknownLabel);
  for (int i = 0; i < 4; ++i) m.add(kUnknownLabel, 2);
  return m;
}

TEST(ConfusionMatrix, HandComputedIoU) {
  const ConfusionMatrix m = fixture();
  // Class 0: TP 5, FP 2 (true 1), FN 1 -> 5/8. Class 1: TP 3, FP 1, FN 3 (2 as 0, 1 unknown) -> 3/7.
  EXPECT_DOUBLE_EQ(m.iou(0), 5.0 / 8.0);
  EXPECT_DOUBLE_EQ(m.iou(1), 3.0 / 7.0);
  EXPECT_TRUE(std::isnan(m.iou(2)));  // neither true nor predicted on labelled pixels
  EXPECT_TRUE(m.present(0));
  EXPECT_FALSE(m.present(2));
  EXPECT_DOUBLE_EQ(m.mean_iou(), (5.0 / 8.0 + 3.0 / 7.0) / 2.0);
  EXPECT_DOUBLE_EQ(m.total(), 12.0);
  EXPECT_DOUBLE_EQ(m.accuracy(), 8.0 / 12.0);
  EXPECT_DOUBLE_EQ(m.count(1, kUnknownLabel), 1.0);
}

TEST(ConfusionMatrix, ImagesFacesAndMerging) {
  ImageI32 truth(3, 1, 1), predicted(3, 1, 1);
  truth.at(0, 0) = 0, truth.at(1, 0) = 1, truth.at(2, 0) = kUnknownLabel;
  predicted.at(0, 0) = 0, predicted.at(1, 0) = 0, predicted.at(2, 0) = 1;
  ConfusionMatrix m(2);
  ASSERT_TRUE(m.add(truth, predicted).ok());
  EXPECT_DOUBLE_EQ(m.iou(0), 0.5);
  EXPECT_EQ(m.add(truth, ImageI32(2, 2, 1)).code(), StatusCode::kInvalidArgument);

  // Faces weigh by area: a 2 m^2 and a 0.5 m^2 triangle.
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
  ConfusionMatrix faces(2);
  ASSERT_TRUE(faces.add_faces(mesh, {0, 1}, {0, 0}).ok());
  EXPECT_DOUBLE_EQ(faces.count(0, 0), 2.0);
  EXPECT_DOUBLE_EQ(faces.count(1, 0), 0.5);
  EXPECT_DOUBLE_EQ(faces.iou(0), 2.0 / 2.5);
  EXPECT_EQ(faces.add_faces(mesh, {0}, {0, 0}).code(), StatusCode::kInvalidArgument);

  ConfusionMatrix sum(2);
  sum.merge(m);
  sum.merge(faces);
  EXPECT_DOUBLE_EQ(sum.count(0, 0), 3.0);

  // Normalised merges: each matrix counts the same, whatever its units.
  ConfusionMatrix equal(2);
  equal.merge(faces, 1.0 / faces.total());
  equal.merge(m, 1.0 / m.total());
  EXPECT_DOUBLE_EQ(equal.total(), 2.0);
  EXPECT_DOUBLE_EQ(equal.count(0, 0), 2.0 / 2.5 + 0.5);
  EXPECT_DOUBLE_EQ(equal.count(1, 0), 0.5 / 2.5 + 0.5);
  equal.merge(faces, std::numeric_limits<double>::infinity());  // an empty matrix's 1 / 0 adds nothing
  EXPECT_DOUBLE_EQ(equal.total(), 2.0);
}

TEST(ConfusionMatrix, TableAndJson) {
  const MaterialTable& t = MaterialTable::paper_default();
  ConfusionMatrix m(t.size());
  m.add(t.find("Wood"), t.find("Wood"), 3);
  m.add(t.find("Metal"), t.find("Wood"), 1);
  const std::string table = m.table(t);
  EXPECT_NE(table.find("| Wood | Metal | mIoU |"), std::string::npos) << table;
  EXPECT_NE(table.find("75.00"), std::string::npos) << table;
  EXPECT_NE(table.find("37.50"), std::string::npos) << table;  // (0.75 + 0) / 2
  const nlohmann::json j = nlohmann::json::parse(m.to_json(t));
  EXPECT_DOUBLE_EQ(j["iou"]["Wood"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(j["miou"].get<double>(), 0.375);
  EXPECT_FALSE(j["iou"].contains("Glass"));
}

TEST(CalibrationBins, HandComputedEce) {
  CalibrationBins bins(10);
  // Bin [0.9, 1): confidence 0.95 x 4, 3 correct -> |0.75 - 0.95| weight 4.
  for (int i = 0; i < 4; ++i) bins.add(0.95f, i < 3);
  // Bin [0.5, 0.6): confidence 0.55 x 2, 1 correct -> |0.5 - 0.55| weight 2.
  bins.add(0.55f, true);
  bins.add(0.55f, false);
  EXPECT_NEAR(bins.expected_calibration_error(), (4 * 0.2 + 2 * 0.05) / 6.0, 1e-6);
  EXPECT_NEAR(bins.accuracy(), 4.0 / 6.0, 1e-12);
  EXPECT_NEAR(bins.mean_confidence(), (4 * 0.95 + 2 * 0.55) / 6.0, 1e-6);
  EXPECT_TRUE(std::isnan(CalibrationBins().expected_calibration_error()));
}

TEST(ConfusionMatrixJson, ReadsBackWhatToJsonWrote) {
  ConfusionMatrix m(3);
  m.add(0, 0, 2.5);
  m.add(0, 1, 0.25);
  m.add(1, kUnknownLabel, 1.0 / 3.0);
  m.add(2, 2, 7.0);
  const MaterialTable& table = MaterialTable::paper_default();
  Result<ConfusionMatrix> back = confusion_matrix_from_json(m.to_json(table), "m.json");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_EQ(back->num_classes(), 3);
  for (int t = 0; t < 3; ++t)
    for (int p = -1; p < 3; ++p)
      EXPECT_DOUBLE_EQ(back->count(t, p < 0 ? kUnknownLabel : p), m.count(t, p < 0 ? kUnknownLabel : p));
  EXPECT_DOUBLE_EQ(back->mean_iou(), m.mean_iou());

  const char* bad[][2] = {
      {"not json", "m.json: expected a confusion matrix"},
      {R"({"matrix_rows_truth_columns_predicted_then_unknown": [[1, 2, 3]]})", "m.json: row 0 must hold 2 numbers"},
      {R"({"matrix_rows_truth_columns_predicted_then_unknown": [[1, -2]]})", "row 0, column 1: expected a finite"},
      {R"({"classes": ["Wood"], "matrix_rows_truth_columns_predicted_then_unknown": [[1, 0, 0], [0, 1, 0]]})",
       "\"classes\" does not list one class per matrix row"},
  };
  for (const auto& [text, message] : bad) {
    Result<ConfusionMatrix> r = confusion_matrix_from_json(text, "m.json");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.status().message().find(message), std::string::npos) << r.status().message();
  }
}

}  // namespace
}  // namespace g2p
