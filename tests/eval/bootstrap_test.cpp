// bootstrap_mean_iou: the interval of a set's per-model mIoU over resampled models.
#include <gtest/gtest.h>

#include "g2p/eval.h"

namespace g2p {
namespace {

// A model of two classes whose faces are all right (weight `right`) or partly
// confused (class 1 taken for class 0 on `wrong` of its weight).
ConfusionMatrix model(double right, double wrong) {
  ConfusionMatrix m(2);
  m.add(0, 0, right);
  m.add(1, 1, right - wrong);
  m.add(1, 0, wrong);
  return m;
}

TEST(BootstrapMeanIou, IdenticalModelsGiveAPointInterval) {
  const std::vector<ConfusionMatrix> models(7, model(10.0, 4.0));
  Result<MeanIouInterval> r = bootstrap_mean_iou(models, 0.9, 200);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_NEAR(r->miou, models[0].mean_iou(), 1e-12);
  EXPECT_NEAR(r->low, r->miou, 1e-12);
  EXPECT_NEAR(r->high, r->miou, 1e-12);
  EXPECT_EQ(r->resamples, 200);
  EXPECT_DOUBLE_EQ(r->confidence, 0.9);
}

// Two models: a resample is both copies of one (a quarter of draws each) or
// one of each, so the 95 % interval runs from the worse model's mIoU to the
// better one's, and the merged mIoU lies inside. Units do not matter: each
// model weighs the same whatever its total.
TEST(BootstrapMeanIou, TwoModelsSpanTheirOwnScores) {
  const ConfusionMatrix good = model(1.0, 0.0), poor = model(5000.0, 4000.0);
  Result<MeanIouInterval> r = bootstrap_mean_iou({good, poor});
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_DOUBLE_EQ(r->low, poor.mean_iou());
  EXPECT_DOUBLE_EQ(r->high, good.mean_iou());
  ConfusionMatrix merged(2);
  merged.merge(good, 1.0 / good.total());
  merged.merge(poor, 1.0 / poor.total());
  EXPECT_NEAR(r->miou, merged.mean_iou(), 1e-12);
  EXPECT_LT(r->low, r->miou);
  EXPECT_GT(r->high, r->miou);
  // Deterministic per seed; a narrower confidence gives an interval inside the wider one.
  Result<MeanIouInterval> again = bootstrap_mean_iou({good, poor});
  EXPECT_EQ(again->low, r->low);
  EXPECT_EQ(again->high, r->high);
  Result<MeanIouInterval> half = bootstrap_mean_iou({good, poor}, 0.5);
  ASSERT_TRUE(half.ok());
  EXPECT_GE(half->low, r->low);
  EXPECT_LE(half->high, r->high);
  EXPECT_LT(half->high - half->low, r->high - r->low);
}

TEST(BootstrapMeanIou, MoreModelsNarrowTheInterval) {
  std::vector<ConfusionMatrix> few, many;
  for (int i = 0; i < 6; ++i) few.push_back(model(10.0, i % 2 ? 6.0 : 1.0));
  for (int i = 0; i < 60; ++i) many.push_back(model(10.0, i % 2 ? 6.0 : 1.0));
  Result<MeanIouInterval> a = bootstrap_mean_iou(few), b = bootstrap_mean_iou(many);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NEAR(a->miou, b->miou, 1e-12);
  EXPECT_LT(b->high - b->low, 0.6 * (a->high - a->low));
  EXPECT_LE(b->low, b->miou);
  EXPECT_GE(b->high, b->miou);
}

TEST(BootstrapMeanIou, RejectsWhatItCannotResample) {
  const ConfusionMatrix m = model(3.0, 1.0);
  EXPECT_EQ(bootstrap_mean_iou({m}, 1.0).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bootstrap_mean_iou({m}, 0.95, 5).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bootstrap_mean_iou({}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bootstrap_mean_iou({ConfusionMatrix(2)}).status().code(), StatusCode::kInvalidArgument);
  Status mixed = bootstrap_mean_iou({m, ConfusionMatrix(3)}).status();
  EXPECT_EQ(mixed.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(mixed.message().find("matrix 1 has 3 classes"), std::string::npos) << mixed.message();
  // Matrices with nothing labelled are left out.
  Result<MeanIouInterval> r = bootstrap_mean_iou({m, ConfusionMatrix(2)}, 0.95, 50);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->low, m.mean_iou(), 1e-12);
  EXPECT_NEAR(r->high, m.mean_iou(), 1e-12);
}

}  // namespace
}  // namespace g2p
