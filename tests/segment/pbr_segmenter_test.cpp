// The weight-free `pbr` segmenter: names in several languages, PBR channels
// when names say nothing, calibrated probabilities, settings.
#include <gtest/gtest.h>

#include <cmath>

#include "g2p/segment.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"

namespace g2p {
namespace {

const MaterialTable& table() { return MaterialTable::paper_default(); }
int label(const char* name) { return table().find(name); }

std::vector<LabelMap> segment_all(const Segmenter& s, const std::vector<View>& views) {
  std::vector<LabelMap> maps(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) EXPECT_TRUE(s.segment_into(views[i], maps[i]).ok());
  return maps;
}

TEST(PbrSegmenter, MaterialNamesInSeveralLanguages) {
  // Neutral grey, mid-rough dielectrics: only the names tell them apart.
  const Eigen::Vector4f grey(0.4f, 0.4f, 0.4f, 1.f);
  const std::vector<test::BoxMaterial> mats = {{"walnut_top", grey, 0.f, 0.5f},       {"Edelstahl", grey, 0.f, 0.5f},
                                               {"velours bleu", grey, 0.f, 0.5f},     {"Cuero_marron", grey, 0.f, 0.5f},
                                               {"porcelana blanca", grey, 0.f, 0.5f}, {"GummiReifen", grey, 0.f, 0.5f}};
  Model model = test::boxes(mats, "PbrSegmenter.Names");
  const std::vector<View> views = test::render(model);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(model, table()).ok());
  const std::vector<LabelMap> maps = segment_all(*s, views);
  const char* expected[] = {"Wood", "Metal", "Fabric", "Leather", "Ceramic", "Rubber"};
  for (int m = 0; m < 6; ++m)
    EXPECT_EQ(test::majority_label(model, views, maps, m), label(expected[m])) << mats[m].name;
}

TEST(PbrSegmenter, PhysicalChannelsWhenNamesSayNothing) {
  const std::vector<test::BoxMaterial> mats = {
      {"material_0", {0.8f, 0.8f, 0.8f, 1.f}, 1.f, 0.3f},  // metallic
      {"material_1",
       {0.9f, 0.9f, 0.9f, 1.f},
       0.f,
       0.05f,
       R"({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}})"},  // transmissive
      {"Material_MR", {0.33f, 0.15f, 0.05f, 1.f}, 0.f, 0.7f},                            // brown, rough
  };
  Model model = test::boxes(mats, "PbrSegmenter.Channels");
  const std::vector<View> views = test::render(model);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(model, table()).ok());
  const std::vector<LabelMap> maps = segment_all(*s, views);
  EXPECT_EQ(test::majority_label(model, views, maps, 0), label("Metal"));
  EXPECT_EQ(test::majority_label(model, views, maps, 1), label("Glass"));
  EXPECT_EQ(test::majority_label(model, views, maps, 2), label("Wood"));
}

TEST(PbrSegmenter, ProbabilitiesAreADistributionOnObjectPixelsOnly) {
  Result<Model> model = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(model.ok());
  const std::vector<View> views = test::render(*model, 2, 48);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(*model, table()).ok());
  for (const View& v : views) {
    Result<LabelMap> map = s->segment(v);
    ASSERT_TRUE(map.ok());
    ASSERT_EQ(map->probabilities.channels(), 12);
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 48; ++x) {
        const float* p = map->probabilities.pixel(x, y);
        float sum = 0.f;
        int argmax = 0;
        for (int c = 0; c < 12; ++c) {
          sum += p[c];
          if (p[c] > p[argmax]) argmax = c;
        }
        if (v.face_id.at(x, y) < 0) {
          EXPECT_EQ(map->labels.at(x, y), kUnknownLabel);
          EXPECT_EQ(sum, 0.f);
        } else {
          EXPECT_NEAR(sum, 1.f, 1e-5f);
          EXPECT_EQ(map->labels.at(x, y), argmax);
        }
      }
    }
  }
}

TEST(PbrSegmenter, SettingsAndErrors) {
  const Eigen::Vector4f grey(0.4f, 0.4f, 0.4f, 1.f);
  Model model = test::boxes({{"oak", grey, 0.f, 0.5f}}, "PbrSegmenter.Settings");
  const std::vector<View> views = test::render(model, 2, 32);
  // names=off: the name no longer decides.
  auto blind = std::move(*make_segmenter("pbr", {{"names", "off"}}));
  ASSERT_TRUE(blind->set_model(model, table()).ok());
  EXPECT_NE(test::majority_label(model, views, segment_all(*blind, views), 0), label("Wood"));
  // A high temperature flattens the distribution.
  auto hot = std::move(*make_segmenter("pbr", {{"temperature", "100"}}));
  auto cold = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(hot->set_model(model, table()).ok());
  ASSERT_TRUE(cold->set_model(model, table()).ok());
  const LabelMap h = *hot->segment(views[0]), c = *cold->segment(views[0]);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      if (views[0].face_id.at(x, y) >= 0) {
        const int l = c.labels.at(x, y);
        EXPECT_LT(h.probabilities.at(x, y, l), c.probabilities.at(x, y, l));
        EXPECT_EQ(h.labels.at(x, y), l);  // the argmax does not move
      }

  EXPECT_EQ(make_segmenter("pbr", {{"colour", "on"}}).status().code(), StatusCode::kInvalidArgument);
  for (const char* t : {"-1", "2x", "inf", "nan", ""})
    EXPECT_EQ(make_segmenter("pbr", {{"temperature", t}}).status().code(), StatusCode::kInvalidArgument) << t;
  EXPECT_EQ(make_segmenter("deeplab").status().code(), StatusCode::kNotFound);
  auto fresh = std::move(*make_segmenter("pbr"));
  EXPECT_EQ(fresh->segment(views[0]).status().code(), StatusCode::kInvalidArgument);  // no set_model
  ASSERT_TRUE(fresh->set_model(model, table()).ok());
  EXPECT_EQ(fresh->segment(View{}).status().code(), StatusCode::kInvalidArgument);  // no face IDs
}

TEST(PbrSegmenter, ObjectNamePrefixSharedByAllNamesCountsLess) {
  // "GlamVelvetSofa_feet": the shared prefix names the object (velvet), the rest the part.
  // The metallic channel then decides; without the prefix rule "velvet" would outvote it.
  const Eigen::Vector4f gold(1.f, 0.8f, 0.7f, 1.f), navy(0.01f, 0.01f, 0.05f, 1.f);
  Model model =
      test::boxes({{"Chesterfield_Velvet_feet", gold, 0.8f, 0.4f}, {"Chesterfield_Velvet_cushion", navy, 0.f, 0.8f}},
                  "PbrSegmenter.Prefix");
  const std::vector<View> views = test::render(model, 3, 48);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(model, table()).ok());
  const std::vector<LabelMap> maps = segment_all(*s, views);
  EXPECT_EQ(test::majority_label(model, views, maps, 0), label("Metal"));
  EXPECT_EQ(test::majority_label(model, views, maps, 1), label("Fabric"));  // cushion: a Fabric word of its own
  // A prefix that is the material word itself still counts (a quarter), e.g. "Fabric_red"/"Fabric_blue".
  const Eigen::Vector4f grey(0.5f, 0.5f, 0.5f, 1.f);
  Model fabrics =
      test::boxes({{"Stoff_rot", grey, 0.f, 0.5f}, {"Stoff_blau", grey, 0.f, 0.5f}}, "PbrSegmenter.Prefix2");
  const std::vector<View> v2 = test::render(fabrics, 2, 32);
  ASSERT_TRUE(s->set_model(fabrics, table()).ok());
  EXPECT_EQ(test::majority_label(fabrics, v2, segment_all(*s, v2), 0), label("Fabric"));
}

TEST(PbrSegmenter, AccentsAndSharpS) {
  const Eigen::Vector4f grey(0.45f, 0.45f, 0.45f, 1.f);
  // "chêne" (oak), "mármol" (marble) and "Gußeisen" (cast iron, with a sharp s).
  Model model = test::boxes({{"ch\xC3\xAAne_clair", grey, 0.f, 0.5f},
                             {"m\xC3\xA1rmol_blanco", grey, 0.f, 0.5f},
                             {"Gu\xC3\x9F"
                              "eisen",
                              grey, 0.f, 0.5f}},
                            "PbrSegmenter.Accents");
  const std::vector<View> views = test::render(model, 3, 48);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(model, table()).ok());
  const std::vector<LabelMap> maps = segment_all(*s, views);
  EXPECT_EQ(test::majority_label(model, views, maps, 0), label("Wood"));
  EXPECT_EQ(test::majority_label(model, views, maps, 1), label("Stone"));
  EXPECT_EQ(test::majority_label(model, views, maps, 2), label("Metal"));  // "gusseisen" holds "eisen"
}

TEST(PbrSegmenter, CustomVocabularyByClassName) {
  Result<MaterialTable> kitchen = MaterialTable::from_json(
      R"({"classes": [{"name": "Steel", "density_kg_m3": 7850}, {"name": "Foam", "density_kg_m3": 30}]})");
  ASSERT_TRUE(kitchen.ok());
  const Eigen::Vector4f grey(0.5f, 0.5f, 0.5f, 1.f);
  Model model =
      test::boxes({{"blue_foam", grey, 0.f, 0.9f}, {"brushed steel", grey, 0.f, 0.5f}}, "PbrSegmenter.Custom");
  const std::vector<View> views = test::render(model, 2, 32);
  auto s = std::move(*make_segmenter("pbr"));
  ASSERT_TRUE(s->set_model(model, *kitchen).ok());
  const std::vector<LabelMap> maps = segment_all(*s, views);
  EXPECT_EQ(test::majority_label(model, views, maps, 0), 1);  // "foam" names the class Foam
  EXPECT_EQ(test::majority_label(model, views, maps, 1), 0);  // "steel" is a Metal word and the class Steel
  EXPECT_EQ(maps[0].probabilities.channels(), 2);
}

}  // namespace
}  // namespace g2p
