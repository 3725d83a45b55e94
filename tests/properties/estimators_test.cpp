// The property estimators and the whole stage on generated objects whose
// right answers are known.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "complete/complete_fixtures.h"
#include "g2p/complete.h"
#include "g2p/io.h"
#include "g2p/properties.h"
#include "g2p/render.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

constexpr int kWood = static_cast<int>(PaperClass::kWood);
constexpr int kMetal = static_cast<int>(PaperClass::kMetal);
constexpr int kGlass = static_cast<int>(PaperClass::kGlass);
constexpr int kPlastic = static_cast<int>(PaperClass::kPlastic);

const MaterialTable& table() { return MaterialTable::paper_default(); }

struct Stage {
  Mesh mesh;
  std::vector<Part> parts;
  Completion completion;
};

Stage complete_object(Mesh mesh, std::vector<Part> parts) {
  Stage s{std::move(mesh), std::move(parts), {}};
  auto c = std::move(*make_completer("partition"));
  Result<Completion> r = c->complete({&s.mesh, &s.parts, &table()});
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  if (r.ok()) s.completion = std::move(*r);
  return s;
}

// As the pipeline completes: a part whose faces already close (the cubes
// below) is kept exactly as given, and the completer is not run.
Stage keep_closed_object(Mesh mesh, std::vector<Part> parts) {
  Stage s{std::move(mesh), std::move(parts), {}};
  auto c = std::move(*make_completer("partition"));
  Result<Completion> r = complete({&s.mesh, &s.parts, &table()}, *c);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  if (r.ok()) s.completion = std::move(*r);
  for (const CompletedPart& p : s.completion.parts) EXPECT_EQ(p.backend, "input") << p.part;
  return s;
}

PropertiesReport report_of(const Stage& s, const std::string& estimator = "table") {
  auto e = std::move(*make_estimator(estimator));
  Result<PropertiesReport> r = estimate_properties(s.mesh, s.parts, s.completion, table(), *e);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? *r : PropertiesReport{};
}

TEST(TableEstimator, HammerIsSolidWithItsCentreOfMassInTheHead) {
  const std::string path = test::scratch_dir("EstimatorHammer") + "/hammer.glb";
  test::make_hammer().write(path);
  Model model = *load_model(path);
  std::vector<Part> parts(2);
  parts[0].label = kMetal;  // the head (material 0)
  parts[1].label = kWood;
  for (int f = 0; f < model.mesh.num_faces(); ++f)
    parts[static_cast<std::size_t>(model.mesh.face_source[static_cast<std::size_t>(f)].material)].faces.push_back(f);
  const Stage s = complete_object(model.mesh, parts);
  const PropertiesReport r = report_of(s);
  ASSERT_EQ(r.parts.size(), 2u);
  for (const PartReport& p : r.parts) EXPECT_EQ(p.properties.structure, Structure::kSolid) << p.part;
  // Head 0.12 x 0.04 x 0.035 m of steel (0.168 litres: below the dense-bulk limit).
  EXPECT_NEAR(r.parts[0].mass.mass_kg, 7800 * 0.12 * 0.04 * 0.035, 0.02 * 7800 * 0.12 * 0.04 * 0.035);
  EXPECT_NEAR(r.object.mass_kg, r.parts[0].mass.mass_kg + r.parts[1].mass.mass_kg, 1e-9);
  // The head spans z 0.30..0.34 (glTF +Y up becomes +Z), x +-0.06, y +-0.0175.
  const Eigen::Vector3d com = r.object.center_of_mass;
  EXPECT_GT(com.z(), 0.30);
  EXPECT_LT(com.z(), 0.34);
  EXPECT_LT(std::abs(com.x()), 0.06);
  EXPECT_LT(std::abs(com.y()), 0.0175);
  EXPECT_LE(r.mass_min_kg, r.object.mass_kg);
  EXPECT_GE(r.mass_max_kg, r.object.mass_kg);
}

TEST(TableEstimator, ModelledInnerWallsMakeAPartHollow) {
  // A glass sphere with its inside modelled: outer r = 0.1 m, inner r = 0.096 m wound inward.
  Mesh shell = test::sphere_mesh(0.1, 48);
  Mesh inner = test::sphere_mesh(0.096, 48);
  for (auto& t : inner.triangles) std::swap(t[1], t[2]);
  test::append_mesh(shell, inner);
  const Stage s = complete_object(shell, test::single_part(shell, kGlass));
  const PropertiesReport r = report_of(s);
  ASSERT_EQ(r.parts.size(), 1u);
  const PartProperties& p = r.parts[0].properties;
  EXPECT_EQ(p.structure, Structure::kHollow);
  EXPECT_EQ(p.structure_source, ValueSource::kGeometry);
  EXPECT_TRUE(p.double_walled);
  EXPECT_GT(p.walls.inner_fraction(), 0.9);
  EXPECT_NEAR(p.wall_thickness_m, 0.004, 0.001);
  // The glass between the two spheres.
  const double glass = 2500 * 4.0 / 3.0 * M_PI * (std::pow(0.1, 3) - std::pow(0.096, 3));
  EXPECT_NEAR(r.object.mass_kg / glass, 1.0, 0.1);
  EXPECT_NEAR(r.object.center_of_mass.norm(), 0.0, 1e-3);
}

TEST(TableEstimator, LargeDensePartsAreShellsSmallOnesSolid) {
  // A closed steel "bottle" (cylinder r 4 cm, 25 cm: 1.26 litres) is a shell
  // of the class's 0.5 mm; a 5 cm steel cube is solid.
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::cylinder_geometry(0.04f, 0.f, 0.25f, 48, p, t);
  const Mesh bottle = test::mesh_from_geometry(p, t);
  PropertiesReport r = report_of(complete_object(bottle, test::single_part(bottle, kMetal)));
  ASSERT_EQ(r.parts.size(), 1u);
  EXPECT_EQ(r.parts[0].properties.structure, Structure::kHollow);
  EXPECT_FALSE(r.parts[0].properties.double_walled);
  const double area = surface_area(bottle);
  EXPECT_NEAR(r.object.mass_kg / (7800 * area * 0.0005), 1.0, 1e-6);

  const Mesh cube = test::box_mesh({0, 0, 0}, {0.05f, 0.05f, 0.05f});
  r = report_of(complete_object(cube, test::single_part(cube, kMetal)));
  ASSERT_EQ(r.parts.size(), 1u);
  EXPECT_EQ(r.parts[0].properties.structure, Structure::kSolid);
  EXPECT_NEAR(r.object.mass_kg / (7800 * 1.25e-4), 1.0, 0.01);
}

TEST(TableEstimator, ThinPartsOfHollowClassesAreSolid) {
  // A 4 mm plastic plate: two 3 mm walls would fill it.
  const Mesh plate = test::box_mesh({0, 0, 0}, {0.2f, 0.1f, 0.004f});
  const PropertiesReport r = report_of(complete_object(plate, test::single_part(plate, kPlastic)));
  ASSERT_EQ(r.parts.size(), 1u);
  EXPECT_EQ(r.parts[0].properties.structure, Structure::kSolid);
  EXPECT_EQ(r.parts[0].properties.structure_source, ValueSource::kGeometry);
  EXPECT_NEAR(r.object.mass_kg / (1150 * 0.2 * 0.1 * 0.004), 1.0, 0.05);
}

// The default table with no class's solid thickness limited, or only Wood's
// (0.10 m) and Metal's (0.06 m), the default table's values
// (docs/materials.md), so that these tests do not move with the others; no
// class's wall is limited.
MaterialTable table_with_limits(double wood_m, double metal_m) {
  std::vector<MaterialClass> classes = table().classes();
  for (MaterialClass& c : classes) c.max_solid_thickness_m = c.max_wall_thickness_m = 0;
  classes[static_cast<std::size_t>(kWood)].max_solid_thickness_m = wood_m;
  classes[static_cast<std::size_t>(kMetal)].max_solid_thickness_m = metal_m;
  return *MaterialTable::from_classes(classes, "limits");
}
const MaterialTable& table_with_solid_limits() {
  static const MaterialTable t = table_with_limits(0.10, 0.06);
  return t;
}
const MaterialTable& table_without_solid_limits() {
  static const MaterialTable t = table_with_limits(0, 0);
  return t;
}

PropertiesReport report_with_table(const Stage& s, const MaterialTable& t) {
  auto e = std::move(*make_estimator("table"));
  Result<PropertiesReport> r = estimate_properties(s.mesh, s.parts, s.completion, t, *e);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? *r : PropertiesReport{};
}
PropertiesReport report_with_solid_limits(const Stage& s) { return report_with_table(s, table_with_solid_limits()); }
PropertiesReport report_without_solid_limits(const Stage& s) {
  return report_with_table(s, table_without_solid_limits());
}

// A part weighed as a single-walled shell of `wall_m`, as the geometry
// decided, whose last note says `why`.
void expect_geometry_shell(const PartProperties& p, double wall_m, const std::string& why) {
  EXPECT_EQ(p.structure, Structure::kHollow);
  EXPECT_FALSE(p.double_walled);
  EXPECT_EQ(p.structure_source, ValueSource::kGeometry);
  EXPECT_DOUBLE_EQ(p.wall_thickness_m, wall_m);
  EXPECT_NE(p.notes.back().find(why), std::string::npos) << p.notes.back();
}

// The thickest solid piece of a class (max_solid_thickness_m): a wardrobe
// modelled as a closed box is panels around air; the same box with no limit
// stays solid wood; a wooden plank stays solid.
TEST(TableEstimator, PartsThickerThanTheirClassesThickestSolidPieceAreShells) {
  const Mesh wardrobe = test::box_mesh({0, 0, 0}, {0.6f, 0.5f, 1.8f});
  const Stage s = complete_object(wardrobe, test::single_part(wardrobe, kWood));
  PropertiesReport r = report_with_solid_limits(s);
  ASSERT_EQ(r.parts.size(), 1u);
  expect_geometry_shell(r.parts[0].properties, 0.02, "more than the thickest solid Wood");
  const double area = surface_area(wardrobe);
  EXPECT_NEAR(r.object.mass_kg / (700 * area * 0.02), 1.0, 1e-6);

  const PropertiesReport solid = report_without_solid_limits(s);
  ASSERT_EQ(solid.parts.size(), 1u);
  EXPECT_EQ(solid.parts[0].properties.structure, Structure::kSolid);
  EXPECT_NEAR(solid.object.mass_kg / (700 * 0.6 * 0.5 * 1.8), 1.0, 0.01);

  const Mesh plank = test::box_mesh({0, 0, 0}, {0.8f, 0.2f, 0.04f});
  r = report_with_solid_limits(complete_object(plank, test::single_part(plank, kWood)));
  ASSERT_EQ(r.parts.size(), 1u);
  EXPECT_EQ(r.parts[0].properties.structure, Structure::kSolid);
  EXPECT_NEAR(r.object.mass_kg / (700 * 0.8 * 0.2 * 0.04), 1.0, 0.01);
}

// Modelled walls that the guards would fill (a 15 cm wooden slab with a
// metal plate in its middle: the plate is 7.4 cm in, and a 7.4 cm shell
// would exceed the slab's volume) still leave a part thicker than the
// thickest solid wood a shell of the class's wall.
TEST(TableEstimator, GuardsDoNotFillAPartThickerThanItsClassesThickestSolidPiece) {
  Mesh object = test::box_mesh({0, 0, 0}, {0.5f, 0.5f, 0.15f});
  const int slab_faces = object.num_faces();
  test::append_mesh(object, test::box_mesh({0.02f, 0.02f, 0.074f}, {0.48f, 0.48f, 0.076f}));
  std::vector<Part> parts(2);
  parts[0].label = kWood;
  parts[1].label = kMetal;
  for (int f = 0; f < object.num_faces(); ++f) parts[f < slab_faces ? 0 : 1].faces.push_back(f);
  const Stage s = complete_object(object, parts);
  const PropertiesReport r = report_with_solid_limits(s);
  ASSERT_EQ(r.parts.size(), 2u);
  const PartProperties& slab = r.parts[0].properties;
  EXPECT_GT(slab.walls.thickness_m, 0.10);
  EXPECT_EQ(slab.structure, Structure::kHollow) << ::testing::PrintToString(slab.notes);
  EXPECT_FALSE(slab.double_walled);
  EXPECT_DOUBLE_EQ(slab.wall_thickness_m, 0.02);
  EXPECT_LT(r.parts[0].mass.mass_kg, 0.6 * 700 * 0.5 * 0.5 * 0.15);
}

// An inner surface farther in than the class's thickest solid piece is
// another part, not the far side of this part's wall: a steel box around a
// box 10 cm inside it is not 10 cm of steel but a sheet-metal shell.
TEST(TableEstimator, AnInnerSurfaceFartherThanAWallCanBeIsNotTheWall) {
  Mesh box = test::box_mesh({-0.25f, -0.25f, -0.25f}, {0.25f, 0.25f, 0.25f});
  Mesh inner = test::box_mesh({-0.15f, -0.15f, -0.15f}, {0.15f, 0.15f, 0.15f});
  for (auto& t : inner.triangles) std::swap(t[1], t[2]);
  test::append_mesh(box, inner);
  const Stage s = complete_object(box, test::single_part(box, kMetal));
  const PropertiesReport r = report_with_solid_limits(s);
  ASSERT_EQ(r.parts.size(), 1u);
  const PartProperties& p = r.parts[0].properties;
  EXPECT_GT(p.walls.inner_fraction(), 0.5);  // the rays do meet the inner box...
  EXPECT_NEAR(p.walls.inner_wall_m, 0.1, 0.01);
  EXPECT_EQ(p.structure, Structure::kHollow);  // ...but the part is a shell of the class's 0.5 mm
  EXPECT_FALSE(p.double_walled);
  EXPECT_DOUBLE_EQ(p.wall_thickness_m, 0.0005);
  bool said = false;
  for (const std::string& n : p.notes) said = said || n.find("another part, not this part's wall") != std::string::npos;
  EXPECT_TRUE(said) << ::testing::PrintToString(p.notes);
  // 10 cm of steel between the boxes would weigh about 760 kg: the default
  // table, with no limit, takes the gap for the wall (and the guard then
  // fills it).
  EXPECT_LT(r.object.mass_kg, 20.0);
  const PropertiesReport unlimited = report_without_solid_limits(s);
  EXPECT_GT(unlimited.object.mass_kg, 300.0);
}

// A modelled wall thicker than the class's thickest single wall
// (max_wall_thickness_m) is a closed section: a steel box with a box 25 mm
// inside it (both faces of its 25 mm panels modelled) is sheet around air,
// every face a wall of the class's 0.5 mm; 25 mm of plate would weigh 265 kg.
// A 4 mm modelled wall is under the limit and stays as measured.
TEST(TableEstimator, ModelledWallsThickerThanTheClassesThickestWallAreClosedSections) {
  auto steel_box = [](float wall_m) {
    Mesh box = test::box_mesh({-0.25f, -0.25f, -0.25f}, {0.25f, 0.25f, 0.25f});
    const float in = 0.25f - wall_m;
    Mesh inner = test::box_mesh({-in, -in, -in}, {in, in, in});
    for (auto& t : inner.triangles) std::swap(t[1], t[2]);
    test::append_mesh(box, inner);
    return box;
  };
  std::vector<MaterialClass> classes = table_with_solid_limits().classes();
  classes[static_cast<std::size_t>(kMetal)].max_wall_thickness_m = 0.006;
  const MaterialTable wall_limit = *MaterialTable::from_classes(classes, "wall limit");

  const Mesh thick = steel_box(0.025f);
  const Stage s = complete_object(thick, test::single_part(thick, kMetal));
  const PropertiesReport plate = report_with_solid_limits(s);
  ASSERT_EQ(plate.parts.size(), 1u);
  EXPECT_NEAR(plate.parts[0].properties.walls.inner_wall_m, 0.025, 0.003);
  EXPECT_TRUE(plate.parts[0].properties.double_walled);
  const double steel_m3 = 0.5 * 0.5 * 0.5 - 0.45 * 0.45 * 0.45;
  EXPECT_NEAR(plate.object.mass_kg / (7800 * steel_m3), 1.0, 0.1);

  const PropertiesReport section = report_with_table(s, wall_limit);
  ASSERT_EQ(section.parts.size(), 1u);
  expect_geometry_shell(section.parts[0].properties, 0.0005,
                        "more than the thickest Metal wall (6 mm): a closed section");
  EXPECT_NEAR(section.object.mass_kg / (7800 * surface_area(thick) * 0.0005), 1.0, 1e-6);

  const Mesh thin = steel_box(0.004f);
  const Stage t = complete_object(thin, test::single_part(thin, kMetal));
  const PropertiesReport sheet = report_with_table(t, wall_limit);
  ASSERT_EQ(sheet.parts.size(), 1u);
  EXPECT_TRUE(sheet.parts[0].properties.double_walled) << ::testing::PrintToString(sheet.parts[0].properties.notes);
  EXPECT_NEAR(sheet.parts[0].properties.wall_thickness_m, 0.004, 0.001);
  EXPECT_NEAR(sheet.object.mass_kg, report_with_solid_limits(t).object.mass_kg, 1e-9);
}

// A scripted vision-language model.
class ScriptedVlm final : public VlmClient {
 public:
  explicit ScriptedVlm(Result<std::string> answer) : answer_(std::move(answer)) {}
  Result<std::string> complete(const VlmRequest& request) const override {
    last_prompt = request.prompt;
    last_images = static_cast<int>(request.images.size());
    return answer_;
  }
  mutable std::string last_prompt;
  mutable int last_images = 0;

 private:
  Result<std::string> answer_;
};

TEST(VlmEstimator, UsesValidAnswersAndFallsBackOnBadOnes) {
  const Mesh cube = test::box_mesh({0, 0, 0}, {0.05f, 0.05f, 0.05f});
  const Stage s = keep_closed_object(cube, test::single_part(cube, kMetal));
  auto estimate = [&](Result<std::string> answer) {
    auto client = std::make_shared<ScriptedVlm>(std::move(answer));
    auto e = make_vlm_estimator(client);
    PropertyInput in{&s.mesh, &s.parts[0], &s.completion.parts[0], &table()};
    Result<PartProperties> p = e->estimate(in);
    EXPECT_TRUE(p.ok()) << p.status().to_string();
    EXPECT_NE(client->last_prompt.find("Metal"), std::string::npos);
    return p.ok() ? *p : PartProperties{};
  };
  // Aluminium, hollow with 2 mm walls.
  PartProperties p = estimate(std::string(
      "Thinking... ```json\n{\"density_kg_m3\": 2700, \"structure\": \"hollow\", \"wall_thickness_m\": 0.002, "
      "\"reason\": \"an aluminium box\"}\n```"));
  EXPECT_EQ(p.density_kg_m3, 2700);
  EXPECT_EQ(p.density_source, ValueSource::kVlm);
  EXPECT_EQ(p.structure, Structure::kHollow);
  EXPECT_EQ(p.wall_thickness_m, 0.002);
  EXPECT_LT(p.density_min_kg_m3, 2700);
  // Out of physical range, a wall thicker than half the part, bad JSON, no answer: the table stands.
  for (Result<std::string> bad :
       {Result<std::string>(std::string("{\"density_kg_m3\": 90000, \"structure\": \"solid\"}")),
        Result<std::string>(
            std::string("{\"density_kg_m3\": 2700, \"structure\": \"hollow\", \"wall_thickness_m\": 0.04}")),
        Result<std::string>(std::string("I cannot tell.")), Result<std::string>(Status::Unavailable("HTTP 503"))}) {
    p = estimate(bad);
    EXPECT_EQ(p.density_kg_m3, 7800);
    EXPECT_EQ(p.density_source, ValueSource::kTable);
    std::string notes;
    for (const auto& n : p.notes) notes += n + "\n";
    EXPECT_NE(notes.find("the table's values stand"), std::string::npos) << notes;
  }
}

TEST(VlmEstimator, ShowsTheModelTheObjectWithThePartColouredIn) {
  const Mesh cube = test::box_mesh({0, 0, 0}, {0.05f, 0.05f, 0.05f});
  const Stage s = keep_closed_object(cube, test::single_part(cube, kMetal));
  Model model;
  model.mesh = cube;
  auto renderer = std::move(*renderer_registry().create("embree"));
  ViewOptions vo;
  vo.width = vo.height = 64;
  const std::vector<View> views = *render_views(*renderer, model, *make_views(model.mesh, vo));
  auto client = std::make_shared<ScriptedVlm>(std::string("{\"density_kg_m3\": 2700, \"structure\": \"solid\"}"));
  auto e = make_vlm_estimator(client);
  ASSERT_TRUE(e->configure({{"max_views", "3"}}).ok());
  PropertyInput in{&s.mesh, &s.parts[0], &s.completion.parts[0], &table(), &views};
  Result<PartProperties> p = e->estimate(in);
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  EXPECT_EQ(p->density_kg_m3, 2700);
  // Every third of the 11 views (0, 4, 8), each as a render and as the part mask.
  EXPECT_EQ(client->last_images, 6);
  EXPECT_NE(client->last_prompt.find("images show"), std::string::npos);
}

TEST(PropertiesReport, JsonHasEveryFieldWithUnits) {
  const Mesh cube = test::box_mesh({0, 0, 0}, {0.1f, 0.1f, 0.1f});
  const PropertiesReport r = report_of(keep_closed_object(cube, test::single_part(cube, kWood)));
  const std::string dir = test::scratch_dir("PropertiesReport");
  ASSERT_TRUE(write_report(dir + "/report.json", r, table()).ok());
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/report.json"));
  EXPECT_EQ(j["format"], "g2p.properties");
  EXPECT_NEAR(j["object"]["mass_kg"].get<double>(), 0.7, 0.007);
  EXPECT_NEAR(j["object"]["center_of_mass_m"][2].get<double>(), 0.05, 1e-3);
  const double i = 0.7 * (0.01 + 0.01) / 12;  // m (a^2 + b^2) / 12
  EXPECT_NEAR(j["object"]["inertia_kg_m2"][0][0].get<double>() / i, 1.0, 0.02);
  const auto& part = j["parts"][0];
  EXPECT_EQ(part["material"], "Wood");
  EXPECT_EQ(part["structure"], "solid");
  EXPECT_TRUE(part["wall_thickness_m"].is_null());
  for (const char* key : {"density_kg_m3", "density_min_kg_m3", "density_max_kg_m3", "mass_kg", "mass_min_kg",
                          "mass_max_kg", "material_volume_m3", "area_m2", "friction_static", "friction_dynamic",
                          "restitution", "mujoco_solref", "mujoco_solimp", "sources", "walls", "completion_ok"})
    EXPECT_TRUE(part.contains(key)) << key;
}

TEST(Estimators, RegistryAndSettings) {
  EXPECT_TRUE(make_estimator("table", {{"rays", "100"}}).ok());
  EXPECT_FALSE(make_estimator("table", {{"rays", "-1"}}).ok());
  EXPECT_FALSE(make_estimator("table", {{"colour", "red"}}).ok());
  EXPECT_TRUE(make_estimator("vlm", {{"max_views", "2"}, {"rays", "10"}}).ok());
  EXPECT_FALSE(make_estimator("oracle").ok());
  // Without a model configured the vlm estimator answers with the table's values.
  const Mesh cube = test::box_mesh({0, 0, 0}, {0.05f, 0.05f, 0.05f});
  const Stage s = keep_closed_object(cube, test::single_part(cube, kWood));
  const PropertiesReport r = report_of(s, "vlm");
  ASSERT_EQ(r.parts.size(), 1u);
  EXPECT_EQ(r.parts[0].properties.density_kg_m3, 700);
}

}  // namespace
}  // namespace g2p
