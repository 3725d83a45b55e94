#include "g2p/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include <nlohmann/json.hpp>

#include "support/test_data.h"

namespace g2p {
namespace {

TEST(MaterialTable, DefaultIsThePapersVocabularyInOrder) {
  const MaterialTable& t = MaterialTable::paper_default();
  ASSERT_EQ(t.size(), 12);
  const char* names[] = {"Wood",  "Rubber",  "Fabric", "Organic", "Leather", "Metal",
                         "Paper", "Plastic", "Glass",  "Ceramic", "Stone",   "Other"};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(t[i].name, names[i]);
  EXPECT_EQ(t.find("metal"), static_cast<int>(PaperClass::kMetal));
  EXPECT_EQ(t.find("GLASS"), static_cast<int>(PaperClass::kGlass));
  EXPECT_EQ(t.find("Unobtainium"), kUnknownLabel);
}

TEST(MaterialTable, DefaultMatchesTheGroundTruthVocabulary) {
  // labels.json (the shared assets' ground truth) names the classes the
  // accuracy tables are computed over: the default table must use the same.
  const nlohmann::json labels = nlohmann::json::parse(test::read_file(test::labels_json_path()));
  const MaterialTable& t = MaterialTable::paper_default();
  ASSERT_EQ(labels["classes"].size(), static_cast<std::size_t>(t.size()));
  for (int i = 0; i < t.size(); ++i) EXPECT_EQ(labels["classes"][i].get<std::string>(), t[i].name);
}

TEST(MaterialTable, DefaultValuesArePhysicallyOrdered) {
  const MaterialTable& t = MaterialTable::paper_default();
  auto density = [&](PaperClass c) { return t[static_cast<int>(c)].density_kg_m3; };
  // Reference values (docs/materials.md): metal > stone > glass > ceramic > plastic ~ organic > wood > fabric.
  EXPECT_GT(density(PaperClass::kMetal), density(PaperClass::kStone));
  EXPECT_GT(density(PaperClass::kGlass), density(PaperClass::kPlastic));
  EXPECT_GT(density(PaperClass::kPlastic), density(PaperClass::kWood));
  EXPECT_GT(density(PaperClass::kWood), density(PaperClass::kFabric));
  EXPECT_EQ(t[static_cast<int>(PaperClass::kMetal)].structure, Structure::kSolid);
  EXPECT_EQ(t[static_cast<int>(PaperClass::kGlass)].structure, Structure::kHollow);
  // The thickest solid piece (accuracy.md, the second structure candidate): none for the classes
  // whose bulk is solid at any size or that the network confuses with bodies (Rubber); otherwise at
  // least two walls, and a wooden leg or beam (0.10 m) thicker than a metal bar (0.06 m).
  for (const PaperClass c :
       {PaperClass::kRubber, PaperClass::kFabric, PaperClass::kOrganic, PaperClass::kStone, PaperClass::kOther})
    EXPECT_EQ(t[static_cast<int>(c)].max_solid_thickness_m, 0.0) << t[static_cast<int>(c)].name;
  EXPECT_DOUBLE_EQ(t[static_cast<int>(PaperClass::kWood)].max_solid_thickness_m, 0.10);
  EXPECT_DOUBLE_EQ(t[static_cast<int>(PaperClass::kMetal)].max_solid_thickness_m, 0.06);
  for (const MaterialClass& c : t.classes())
    if (c.max_solid_thickness_m > 0) EXPECT_GE(c.max_solid_thickness_m, 2 * c.wall_thickness_m) << c.name;
  // The thickest wall (accuracy.md, the third structure candidate): only Metal's, where sheet
  // ends and plate begins.
  for (const MaterialClass& c : t.classes())
    if (c.name != "Metal") EXPECT_EQ(c.max_wall_thickness_m, 0.0) << c.name;
  EXPECT_DOUBLE_EQ(t[static_cast<int>(PaperClass::kMetal)].max_wall_thickness_m, 0.006);
  for (const MaterialClass& c : t.classes()) {
    EXPECT_LE(c.density_min_kg_m3, c.density_kg_m3) << c.name;
    EXPECT_GE(c.density_max_kg_m3, c.density_kg_m3) << c.name;
    EXPECT_FALSE(c.source.empty()) << c.name << " has no documented source";
  }
}

TEST(MaterialTable, JsonRoundTripKeepsEveryField) {
  const MaterialTable& t = MaterialTable::paper_default();
  Result<MaterialTable> back = MaterialTable::from_json(t.to_json());
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_EQ(back->size(), t.size());
  EXPECT_EQ(back->name(), t.name());
  for (int i = 0; i < t.size(); ++i) {
    const MaterialClass &a = t[i], &b = (*back)[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.color, b.color);
    EXPECT_DOUBLE_EQ(a.density_kg_m3, b.density_kg_m3);
    EXPECT_DOUBLE_EQ(a.density_min_kg_m3, b.density_min_kg_m3);
    EXPECT_DOUBLE_EQ(a.density_max_kg_m3, b.density_max_kg_m3);
    EXPECT_DOUBLE_EQ(a.friction_static, b.friction_static);
    EXPECT_DOUBLE_EQ(a.friction_dynamic, b.friction_dynamic);
    EXPECT_DOUBLE_EQ(a.restitution, b.restitution);
    EXPECT_EQ(a.structure, b.structure);
    EXPECT_DOUBLE_EQ(a.wall_thickness_m, b.wall_thickness_m);
    EXPECT_DOUBLE_EQ(a.max_solid_thickness_m, b.max_solid_thickness_m);
    EXPECT_DOUBLE_EQ(a.max_wall_thickness_m, b.max_wall_thickness_m);
    EXPECT_EQ(a.source, b.source);
  }
}

// The thickness limits (the thickest solid piece, the thickest wall): read,
// written only when set, kept through a round trip, and checked.
TEST(MaterialTable, TheThicknessLimitsAreReadAndWrittenAndChecked) {
  Result<MaterialTable> t = MaterialTable::from_json(
      R"({"classes": [{"name": "Steel", "density_kg_m3": 7800, "wall_thickness_m": 0.001,
                       "max_solid_thickness_m": 0.06, "max_wall_thickness_m": 0.006},
                      {"name": "Foam", "density_kg_m3": 30}]})");
  ASSERT_TRUE(t.ok()) << t.status().to_string();
  Result<MaterialTable> back = MaterialTable::from_json(t->to_json());
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  const std::string json = t->to_json();
  for (const auto& [key, field, value] :
       {std::make_tuple("max_solid_thickness_m", &MaterialClass::max_solid_thickness_m, 0.06),
        std::make_tuple("max_wall_thickness_m", &MaterialClass::max_wall_thickness_m, 0.006)}) {
    EXPECT_DOUBLE_EQ((*t)[0].*field, value) << key;
    EXPECT_DOUBLE_EQ((*t)[1].*field, 0.0) << key;  // no limit unless given
    EXPECT_DOUBLE_EQ((*back)[0].*field, value) << key;
    EXPECT_EQ(json.find(key), json.rfind(key)) << key << ": written for the class that sets it only\n" << json;
    std::vector<MaterialClass> classes = t->classes();
    classes[0].*field = std::nan("");
    EXPECT_FALSE(MaterialTable::from_classes(classes).ok()) << key;
    classes[0].*field = -0.001;
    EXPECT_FALSE(MaterialTable::from_classes(classes).ok()) << key;
  }
}

TEST(MaterialTable, CustomVocabularyWithDefaults) {
  Result<MaterialTable> t = MaterialTable::from_json(
      R"({"name": "kitchen", "classes": [
           {"name": "Steel", "density_kg_m3": 7850},
           {"name": "Foam", "density_kg_m3": 30, "density_range_kg_m3": [10, 60], "friction": 0.9,
            "structure": "hollow", "wall_thickness_m": 0.01, "color": [1, 2, 3]}]})");
  ASSERT_TRUE(t.ok()) << t.status().to_string();
  EXPECT_EQ(t->name(), "kitchen");
  ASSERT_EQ(t->size(), 2);
  EXPECT_DOUBLE_EQ((*t)[0].density_min_kg_m3, 7850.0);  // no range: the nominal value
  EXPECT_DOUBLE_EQ((*t)[1].friction_static, 0.9);
  EXPECT_DOUBLE_EQ((*t)[1].friction_dynamic, 0.9);
  EXPECT_EQ((*t)[1].structure, Structure::kHollow);
  EXPECT_EQ((*t)[1].color[2], 3);
}

struct BadTable {
  const char* json;
  StatusCode code;
  const char* message_part;
};

class MaterialTableErrors : public testing::TestWithParam<BadTable> {};

TEST_P(MaterialTableErrors, NameWhatAndWhere) {
  Result<MaterialTable> t = MaterialTable::from_json(GetParam().json, "table.json");
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), GetParam().code) << t.status().to_string();
  EXPECT_NE(t.status().message().find("table.json"), std::string::npos) << t.status().message();
  EXPECT_NE(t.status().message().find(GetParam().message_part), std::string::npos) << t.status().message();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, MaterialTableErrors,
    testing::Values(BadTable{"{not json", StatusCode::kParseError, "not valid JSON"},
                    BadTable{"[1, 2]", StatusCode::kParseError, "object at the top level"},
                    BadTable{R"({"name": "x"})", StatusCode::kParseError, "missing array 'classes'"},
                    BadTable{R"({"classes": []})", StatusCode::kInvalidArgument, "has no classes"},
                    BadTable{R"({"classes": [{"density_kg_m3": 1}]})", StatusCode::kParseError,
                             "classes[0]: missing string 'name'"},
                    BadTable{R"({"classes": [{"name": "A"}]})", StatusCode::kParseError, "missing 'density_kg_m3'"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": -5}]})", StatusCode::kInvalidArgument,
                             "class 'A': density_kg_m3 must be > 0"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 500, "density_range_kg_m3": [600, 900]}]})",
                             StatusCode::kInvalidArgument, "must be positive and contain density_kg_m3"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "restitution": 1.5}]})",
                             StatusCode::kInvalidArgument, "restitution must lie in [0, 1]"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "structure": "spongy"}]})",
                             StatusCode::kParseError, "'structure' must be"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "color": [1, 2, 300]}]})",
                             StatusCode::kParseError, "'color' must be"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5}, {"name": "a", "density_kg_m3": 6}]})",
                             StatusCode::kInvalidArgument, "classes[1]: name 'a' repeats classes[0]"},
                    BadTable{R"({"format": "g2p-material-table", "version": 99, "classes": []})",
                             StatusCode::kUnsupported, "newer than this libg2p reads"},
                    BadTable{R"({"version": "1", "classes": []})", StatusCode::kParseError,
                             "'version' must be an integer"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "restitutoin": 0.2}]})",
                             StatusCode::kParseError, "classes[0]: unknown key 'restitutoin'"},
                    BadTable{R"({"clases": []})", StatusCode::kParseError, "unknown key 'clases'"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "wall_thickness_m": 0.02,
                                  "max_solid_thickness_m": 0.03}]})",
                             StatusCode::kInvalidArgument, "class 'A': max_solid_thickness_m must be 0 (no limit) or"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "wall_thickness_m": 0.02,
                                  "max_wall_thickness_m": 0.01}]})",
                             StatusCode::kInvalidArgument,
                             "class 'A': max_wall_thickness_m must be 0 (no limit) or at least wall_thickness_m"},
                    BadTable{R"({"classes": [{"name": "A", "density_kg_m3": 5, "wall_thickness_m": 0.001,
                                  "max_solid_thickness_m": 0.01, "max_wall_thickness_m": 0.01}]})",
                             StatusCode::kInvalidArgument,
                             "class 'A': max_wall_thickness_m (0.01) must be less than max_solid_thickness_m (0.01)"}),
    [](const testing::TestParamInfo<BadTable>& info) { return "case" + std::to_string(info.index); });

TEST(MaterialTable, LoadAndSaveFiles) {
  const std::string dir = test::scratch_dir("MaterialTable.LoadAndSaveFiles");
  Result<MaterialTable> missing = MaterialTable::load(dir + "/none.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);

  const std::string path = dir + "/table.json";
  ASSERT_TRUE(MaterialTable::paper_default().save(path).ok());
  Result<MaterialTable> loaded = MaterialTable::load(path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().to_string();
  EXPECT_EQ(loaded->size(), 12);

  // The shipped data file is the embedded default.
  Result<MaterialTable> shipped = MaterialTable::load(test::source_path("libg2p/data/materials.json"));
  ASSERT_TRUE(shipped.ok()) << shipped.status().to_string();
  EXPECT_TRUE(shipped->to_json() == MaterialTable::paper_default().to_json())
      << "libg2p/data/materials.json differs from the table embedded in the library";

  // Saving into a folder that does not exist fails cleanly and leaves nothing.
  EXPECT_EQ(MaterialTable::paper_default().save(dir + "/no/such/dir/t.json").code(), StatusCode::kIoError);
}

}  // namespace
}  // namespace g2p
