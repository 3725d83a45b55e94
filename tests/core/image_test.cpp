#include "g2p/image.h"

#include <gtest/gtest.h>

namespace g2p {
namespace {

TEST(Image, RowMajorInterleavedLayout) {
  ImageU8 img(4, 3, 3);
  EXPECT_EQ(img.size(), 4u * 3u * 3u);
  EXPECT_EQ(img.row_stride(), 12u);
  img.at(2, 1, 0) = 10;
  img.at(2, 1, 2) = 30;
  // Pixel (x=2, y=1) starts at (1 * 4 + 2) * 3.
  EXPECT_EQ(img.data()[18], 10);
  EXPECT_EQ(img.data()[20], 30);
  EXPECT_EQ(img.pixel(2, 1)[2], 30);
}

TEST(Image, FillAndEquality) {
  ImageI32 a(5, 2, 1, -1), b(5, 2, 1, -1);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.at(4, 1), -1);
  b.at(0, 0) = 7;
  EXPECT_NE(a, b);
  EXPECT_NE(a, ImageI32(2, 5, 1, -1));  // same size, other shape
}

TEST(Image, DefaultIsEmpty) {
  ImageF img;
  EXPECT_TRUE(img.empty());
  EXPECT_EQ(img.width(), 0);
}

}  // namespace
}  // namespace g2p
