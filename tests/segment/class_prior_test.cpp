// apply_class_prior: a prior over classes on the pixels the image decided.
#include <gtest/gtest.h>

#include "g2p/segment.h"

namespace g2p {
namespace {

// Three pixels of three faces, two classes: face 0 a close call (0.55 for
// class 0), face 1 sure of class 0 (0.95), face 2 a close call the segmenter
// did not decide from the image.
struct Fixture {
  View view;
  LabelMap map;
  std::vector<std::uint8_t> image_decided{1, 1, 0};
  Fixture() {
    view.face_id = ImageI32(3, 1, 1, -1);
    for (int x = 0; x < 3; ++x) view.face_id.at(x, 0) = x;
    map.labels = ImageI32(3, 1, 1, 0);
    map.probabilities = ImageF(3, 1, 2);
    const float first[3] = {0.55f, 0.95f, 0.55f};
    for (int x = 0; x < 3; ++x) {
      map.probabilities.at(x, 0, 0) = first[x];
      map.probabilities.at(x, 0, 1) = 1.0f - first[x];
    }
  }
};

TEST(ClassPrior, TipsCloseCallsTheImageDecidedAndLeavesTheRest) {
  Fixture f;
  // Class 0 is not among the kind's materials: weight 0.5.
  Result<std::size_t> changed = apply_class_prior({0.5f, 1.0f}, f.image_decided, f.view, f.map);
  ASSERT_TRUE(changed.ok()) << changed.status().to_string();
  EXPECT_EQ(*changed, 1u);
  EXPECT_EQ(f.map.labels.at(0, 0), 1);  // 0.275 against 0.45: the kind tips it
  EXPECT_NEAR(f.map.probabilities.at(0, 0, 1), 0.45 / 0.725, 1e-5);
  EXPECT_EQ(f.map.labels.at(1, 0), 0);  // 0.475 against 0.05: the image still decides
  EXPECT_NEAR(f.map.probabilities.at(1, 0, 0) + f.map.probabilities.at(1, 0, 1), 1.0, 1e-6);
  EXPECT_EQ(f.map.labels.at(2, 0), 0);  // names decided it: untouched
  EXPECT_FLOAT_EQ(f.map.probabilities.at(2, 0, 0), 0.55f);
}

TEST(ClassPrior, NoPriorOrNoProbabilitiesChangeNothingAndBadWeightsAreErrors) {
  Fixture f;
  const LabelMap before = f.map;
  ASSERT_TRUE(apply_class_prior({}, f.image_decided, f.view, f.map).ok());
  EXPECT_EQ(f.map.labels, before.labels);
  EXPECT_EQ(f.map.probabilities, before.probabilities);
  LabelMap hard;
  hard.labels = before.labels;  // a backend that gives labels only
  Result<std::size_t> changed = apply_class_prior({0.1f, 1.0f}, f.image_decided, f.view, hard);
  ASSERT_TRUE(changed.ok());
  EXPECT_EQ(*changed, 0u);
  EXPECT_EQ(hard.labels, before.labels);
  EXPECT_EQ(apply_class_prior({1.0f}, f.image_decided, f.view, f.map).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(apply_class_prior({0.0f, 1.0f}, f.image_decided, f.view, f.map).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(f.map.labels, before.labels);
}

}  // namespace
}  // namespace g2p
