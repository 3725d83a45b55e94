// mass_errors against hand-computed NeRF2Physics metrics.
#include <gtest/gtest.h>

#include <cmath>

#include "g2p/eval.h"

namespace g2p {
namespace {

TEST(MassErrors, MatchHandComputedValues) {
  Result<MassErrors> e = mass_errors({2.0, 1.0, 3.0}, {1.0, 2.0, 3.0});
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e->objects, 3);
  EXPECT_NEAR(e->ade_kg, (1.0 + 1.0 + 0.0) / 3, 1e-12);
  EXPECT_NEAR(e->alde, 2 * std::log(2.0) / 3, 1e-12);
  EXPECT_NEAR(e->ape, (1.0 + 0.5 + 0.0) / 3, 1e-12);
  EXPECT_NEAR(e->mnre, (0.5 + 0.5 + 1.0) / 3, 1e-12);
}

TEST(MassErrors, RejectsBadInput) {
  EXPECT_FALSE(mass_errors({}, {}).ok());
  EXPECT_FALSE(mass_errors({1.0}, {1.0, 2.0}).ok());
  Result<MassErrors> e = mass_errors({1.0, 0.0}, {1.0, 1.0});
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("object 1"), std::string::npos);
  EXPECT_FALSE(mass_errors({1.0}, {NAN}).ok());
}

}  // namespace
}  // namespace g2p
