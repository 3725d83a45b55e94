#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/segment.h"
#include "support/test_data.h"

namespace g2p {
namespace {

TEST(LabelMaps, ColoursLegendAndFiles) {
  const MaterialTable& t = MaterialTable::paper_default();
  LabelMap map;
  map.labels = ImageI32(4, 2, 1, kUnknownLabel);
  map.labels.at(1, 0) = t.find("Metal");
  map.labels.at(3, 1) = t.find("Wood");
  map.probabilities = ImageF(4, 2, t.size(), 0.f);
  map.probabilities.at(1, 0, t.find("Metal")) = 1.f;

  const ImageU8 colours = colorize_labels(map.labels, t, {7, 8, 9});
  EXPECT_EQ(colours.at(0, 0, 0), 7);  // unknown: the background colour
  for (int c = 0; c < 3; ++c) EXPECT_EQ(colours.at(1, 0, c), t[t.find("Metal")].color[c]);

  const ImageU8 legend = label_legend(t);
  EXPECT_EQ(legend.height(), 22 * 12 + 8);

  const std::string dir = test::scratch_dir("LabelMaps.Files");
  ASSERT_TRUE(write_label_maps(dir, {map, map}, t).ok());
  Result<ImageU8> index = read_image(dir + "/view_01_labels_index.png");
  ASSERT_TRUE(index.ok());
  EXPECT_EQ(index->at(0, 0, 0), 255);
  EXPECT_EQ(index->at(1, 0, 0), t.find("Metal"));
  EXPECT_EQ(index->at(3, 1, 0), t.find("Wood"));
  Result<ImageU8> sheet = read_image(dir + "/view_00_labels.png");
  ASSERT_TRUE(sheet.ok());
  EXPECT_EQ(sheet->width(), 4 + legend.width());  // labels with the legend beside them
  const std::string npy = test::read_file(dir + "/view_00_probs.npy");
  EXPECT_NE(npy.find("'shape': (2, 4, 12)"), std::string::npos);
  const nlohmann::json classes = nlohmann::json::parse(test::read_file(dir + "/classes.json"));
  EXPECT_EQ(classes["classes"][5]["name"], "Metal");
  EXPECT_TRUE(std::filesystem::exists(dir + "/legend.png"));
  Result<ImageU8> contact = read_image(dir + "/contact_sheet.png");
  ASSERT_TRUE(contact.ok());
  EXPECT_EQ(contact->width(), 3 * (256 + 4) + 4);  // two views and the legend
  EXPECT_EQ(write_label_maps(dir, {}, t).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace g2p
