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

// Forty models from easy to hard; B fixes a fifth of A's errors on every one.
// Separately, the two intervals overlap (which models were drawn moves both
// alike); paired, the gain is resolved.
TEST(BootstrapMeanIouDifference, AConsistentGainIsResolvedWhereSeparateIntervalsOverlap) {
  std::vector<ConfusionMatrix> a, b;
  for (int i = 0; i < 40; ++i) {
    const double wrong = 1.0 + 2.0 * (i % 5);
    a.push_back(model(10.0, wrong));
    b.push_back(model(10.0, 0.8 * wrong));
  }
  Result<MeanIouDifference> d = bootstrap_mean_iou_difference(a, b);
  Result<MeanIouInterval> ia = bootstrap_mean_iou(a), ib = bootstrap_mean_iou(b);
  ASSERT_TRUE(d.ok() && ia.ok() && ib.ok()) << d.status().to_string();
  EXPECT_NEAR(d->miou_a, ia->miou, 1e-12);
  EXPECT_NEAR(d->miou_b, ib->miou, 1e-12);
  EXPECT_NEAR(d->difference, ib->miou - ia->miou, 1e-12);
  EXPECT_GT(d->difference, 0.0);
  EXPECT_LT(ib->low, ia->high);  // separately: not told apart
  EXPECT_GT(d->low, 0.0);        // paired: told apart
  EXPECT_LE(d->low, d->difference);
  EXPECT_GE(d->high, d->difference);
  EXPECT_EQ(d->models, 40);
  EXPECT_EQ(d->resamples, 2000);
  // B against itself: a point interval at zero; swapped sides: the mirrored interval.
  Result<MeanIouDifference> same = bootstrap_mean_iou_difference(b, b);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->difference, 0.0);
  EXPECT_EQ(same->low, 0.0);
  EXPECT_EQ(same->high, 0.0);
  Result<MeanIouDifference> swapped = bootstrap_mean_iou_difference(b, a);
  ASSERT_TRUE(swapped.ok());
  EXPECT_NEAR(swapped->low, -d->high, 1e-12);
  EXPECT_NEAR(swapped->high, -d->low, 1e-12);
}

TEST(BootstrapMeanIouDifference, RejectsUnpairedModels) {
  const ConfusionMatrix m = model(10.0, 2.0);
  Status s = bootstrap_mean_iou_difference({m, m}, {m}).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("2 models against 1"), std::string::npos) << s.message();
  s = bootstrap_mean_iou_difference({m, model(10.0, 1.0)}, {m, model(12.0, 1.0)}).status();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("model 1 has other ground truth"), std::string::npos) << s.message();
  // The same truth predicted otherwise is what a comparison is for.
  EXPECT_TRUE(bootstrap_mean_iou_difference({model(10.0, 1.0)}, {model(10.0, 9.0)}, 0.95, 20).ok());
  s = bootstrap_mean_iou_difference({m}, {ConfusionMatrix(3)}).status();
  EXPECT_NE(s.message().find("matrix 0 has 3 classes"), std::string::npos) << s.message();
  EXPECT_EQ(bootstrap_mean_iou_difference({}, {}).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bootstrap_mean_iou_difference({m}, {m}, 0.0).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p
