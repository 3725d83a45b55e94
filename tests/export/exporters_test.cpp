// Exported assets in the real consumers: MuJoCo compiles and simulates the
// MJCF, urdfdom (and check_urdf) reads the URDF, TinyXML the SDF.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>
#ifdef G2P_TEST_WITH_SDFORMAT
#include <sdf/Link.hh>
#include <sdf/Model.hh>
#include <sdf/Root.hh>
#endif

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "export/export_fixtures.h"
#include "g2p/complete.h"
#include "g2p/export.h"
#include "g2p/io.h"
#include "g2p/overrides.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/segment.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

constexpr int kWood = static_cast<int>(PaperClass::kWood);
constexpr int kMetal = static_cast<int>(PaperClass::kMetal);

// The generated hammer through stages 5 and 6; `head_label` is the head's class.
SimulationAsset hammer_asset(int head_label, Model* model_out = nullptr, std::vector<Part>* parts_out = nullptr) {
  const std::string path = test::scratch_dir("ExportHammer") + "/hammer.glb";
  test::make_hammer().write(path);
  const Model model = *load_model(path);
  if (model_out != nullptr) *model_out = model;
  std::vector<Part> parts(2);
  parts[0].label = head_label;
  parts[1].label = kWood;
  for (int f = 0; f < model.mesh.num_faces(); ++f)
    parts[static_cast<std::size_t>(model.mesh.face_source[static_cast<std::size_t>(f)].material)].faces.push_back(f);
  const MaterialTable& table = MaterialTable::paper_default();
  const Completion completion = *(*make_completer("partition"))->complete({&model.mesh, &parts, &table});
  const PropertiesReport report = *estimate_properties(model.mesh, parts, completion, table, **make_estimator("table"));
  if (parts_out != nullptr) *parts_out = parts;
  Result<SimulationAsset> asset = make_asset("hammer", model.mesh, parts, completion, report, table);
  EXPECT_TRUE(asset.ok()) << asset.status().to_string();
  return *asset;
}

void expect_relative(double got, double want, double tolerance, const char* what) {
  EXPECT_NEAR(got, want, tolerance * std::abs(want)) << what;
}

// MuJoCo compiled the asset with libg2p's mass, centre of mass and inertia.
void expect_mujoco_agrees(const EngineCheck& c, const SimulationAsset& asset) {
  expect_relative(c.mass_kg, asset.total.mass_kg, 1e-6, "mass");
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(c.center_of_mass[a], asset.total.center_of_mass[a], 1e-6);
  const Eigen::Vector3d ours = asset.total.principal_moments();
  for (int a = 0; a < 3; ++a) expect_relative(c.principal_moments[a], ours[a], 1e-6, "principal moment");
}

TEST(Exporters, MujocoCompilesTheHammerWithLibg2psMassProperties) {
  const SimulationAsset asset = hammer_asset(kMetal);
  const std::string dir = test::scratch_dir("ExportMjcf");
  ASSERT_TRUE(write_asset(dir, asset, {"mjcf", "urdf", "sdf"}).ok());
  // 3 s: with contacts scaled to the hammer (#50) it lands upright on its
  // handle's end without sinking, balances for about a second, then topples.
  Result<EngineCheck> c = check_in_mujoco(dir + "/hammer.xml", 0.2, 3.0);
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  expect_mujoco_agrees(*c, asset);
  // Dropped on a plane it comes to rest without exploding or sinking through.
  EXPECT_TRUE(c->dropped);
  EXPECT_TRUE(c->finite);
  // MuJoCo's contacts are soft: a little penetration on impact, less at rest.
  EXPECT_GT(c->lowest_point_m, -0.03);
  EXPECT_GT(c->resting_lowest_m, -0.005);
  EXPECT_LT(c->resting_lowest_m, 0.005);
  EXPECT_LT(c->final_speed_m_s, 0.05);
  // The folder is relocatable: the files name their meshes relatively.
  for (const char* f : {"hammer.xml", "hammer.urdf", "hammer.sdf"})
    EXPECT_EQ(test::read_file(dir + "/" + f).find(dir), std::string::npos) << f;
}

// g2p validate's check of a folder: the engine's numbers beside the report's,
// which a wrong report fails.
TEST(Exporters, AFolderCheckComparesTheEngineWithTheReport) {
  if (!have_mujoco()) GTEST_SKIP() << "libg2p built without MuJoCo";
  const SimulationAsset asset = hammer_asset(kMetal);
  const std::string dir = test::scratch_dir("ExportFolderCheck");
  ASSERT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  Result<FolderCheck> alone = check_folder_in_mujoco(dir);
  ASSERT_TRUE(alone.ok()) << alone.status().to_string();
  EXPECT_EQ(alone->mjcf, dir + "/hammer.xml");
  EXPECT_FALSE(alone->has_report);
  EXPECT_TRUE(alone->pass());
  const Eigen::Vector3d c = asset.total.center_of_mass, m = asset.total.principal_moments();
  auto report = [&](double mass) {
    test::write_file(dir + "/report.json", nlohmann::json{{"object",
                                                           {{"mass_kg", mass},
                                                            {"center_of_mass_m", {c.x(), c.y(), c.z()}},
                                                            {"principal_moments_kg_m2", {m.x(), m.y(), m.z()}}}}}
                                               .dump());
    return check_folder_in_mujoco(dir);
  };
  Result<FolderCheck> same = report(asset.total.mass_kg);
  ASSERT_TRUE(same.ok());
  EXPECT_TRUE(same->has_report);
  EXPECT_TRUE(same->numbers_match);
  EXPECT_TRUE(same->drop_ok);
  Result<FolderCheck> wrong = report(asset.total.mass_kg * 1.01);
  ASSERT_TRUE(wrong.ok());
  EXPECT_FALSE(wrong->numbers_match);
  EXPECT_FALSE(wrong->pass());
  EXPECT_EQ(check_folder_in_mujoco(dir + "/none").status().code(), StatusCode::kNotFound);
  // The drop's line says whether the body came to rest: 0.1 s after its
  // release from 0.2 m the hammer is still falling; after 8 s it lies still
  // (3 s in the release build; the sanitizer build's hulls, a few micrometres
  // apart, leave it rocking on its handle until 5 s with the elliptic cone).
  auto drop = [&](double seconds, bool at_rest) {
    Result<FolderCheck> check = check_folder_in_mujoco(dir, 0.2, seconds);
    ASSERT_TRUE(check.ok());
    EXPECT_EQ(check->engine.final_speed_m_s < 0.005, at_rest) << check->engine.final_speed_m_s;
    const std::string text = folder_check_text(*check);
    EXPECT_EQ(text.find(", at rest (") != std::string::npos, at_rest) << text;
    EXPECT_EQ(text.find("still moving") != std::string::npos, !at_rest) << text;
    EXPECT_EQ(text.find("--seconds longer") != std::string::npos, !at_rest) << text;
  };
  drop(0.1, false);
  drop(8.0, true);
}

// |angular acceleration| of the hammer hinged on a horizontal axis (body y)
// through its bounding-box centre, handle horizontal, released from rest.
double hinge_acceleration(const SimulationAsset& asset, const std::string& dir, double& predicted) {
  EXPECT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  std::string xml = test::read_file(dir + "/hammer.xml");
  Eigen::AlignedBox3d box;
  for (const AssetPart& p : asset.parts) box.extend(bounds(p.closed));
  const Eigen::Vector3d hinge = box.center();
  char joint[256];
  std::snprintf(joint, sizeof joint, "<joint name=\"hinge\" type=\"hinge\" axis=\"0 1 0\" pos=\"%.9g %.9g %.9g\"/>",
                hinge.x(), hinge.y(), hinge.z());
  const std::string free = "<freejoint name=\"hammer_free\"/>";
  const std::size_t at = xml.find(free);
  EXPECT_NE(at, std::string::npos);
  xml.replace(at, free.size(), joint);
  // Turn the body so its +Z (the handle) lies along world +X.
  const std::string open = "<body name=\"hammer\">";
  xml.replace(xml.find(open), open.size(), "<body name=\"hammer\" quat=\"0.70710678 0 0.70710678 0\">");
  test::write_file(dir + "/hinged.xml", xml);
  char error[1000] = "";
  mjModel* m = mj_loadXML((dir + "/hinged.xml").c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  if (m == nullptr) return 0;
  mjData* d = mj_makeData(m);
  mj_forward(m, d);
  const double qacc = d->qacc[0];
  mj_deleteData(d);
  mj_deleteModel(m);
  // m g d / I about the hinge: d is the centre of mass's offset along the
  // handle (horizontal), I the moment about the hinge axis.
  const MassProperties& t = asset.total;
  const Eigen::Vector3d r = t.center_of_mass - hinge;
  const double inertia = t.inertia(1, 1) + t.mass_kg * (r.x() * r.x() + r.z() * r.z());
  predicted = t.mass_kg * 9.81 * std::abs(r.z()) / inertia;
  return std::abs(qacc);
}

TEST(Exporters, HingedHammerSwingsHeadDownAsPhysicsSays) {
  double predicted = 0, predicted_uniform = 0;
  const double two_materials = hinge_acceleration(hammer_asset(kMetal), test::scratch_dir("ExportHinge"), predicted);
  EXPECT_NEAR(two_materials / predicted, 1.0, 0.01);
  // Uniform density (all wood): the centre of mass sits near the geometric
  // centre, and the hammer swings measurably less.
  const double uniform =
      hinge_acceleration(hammer_asset(kWood), test::scratch_dir("ExportHingeUniform"), predicted_uniform);
  EXPECT_NEAR(uniform / predicted_uniform, 1.0, 0.01);
  EXPECT_LT(uniform, 0.8 * two_materials) << "uniform " << uniform << " vs two materials " << two_materials;
}

// A glass bottle (a closed cylinder, r 4 cm, 25 cm tall, +Z up), one part,
// through stages 5 and 6 with `overrides` (empty: none) and out as MJCF.
SimulationAsset bottle_asset(const std::string& overrides_json, PropertiesReport* report_out = nullptr) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::cylinder_geometry(0.04f, 0.f, 0.25f, 64, p, t);
  for (Eigen::Vector3f& v : p) v = Eigen::Vector3f(v.x(), -v.z(), v.y());  // glTF +Y up to +Z up
  const Mesh mesh = test::mesh_from_geometry(p, t);
  std::vector<Part> parts(1);
  parts[0].label = static_cast<int>(PaperClass::kGlass);
  for (int f = 0; f < mesh.num_faces(); ++f) parts[0].faces.push_back(f);
  const MaterialTable& table = MaterialTable::paper_default();
  const Completion completion = *(*make_completer("partition"))->complete({&mesh, &parts, &table});
  const std::unique_ptr<PropertyEstimator> base = *make_estimator("table");
  Result<Overrides> o = parse_overrides(overrides_json, table);
  EXPECT_TRUE(o.ok()) << o.status().to_string();
  const std::vector<int> labels(static_cast<std::size_t>(mesh.num_faces()), parts[0].label);
  const ResolvedOverrides resolved = *resolve_overrides(*o, mesh.num_faces(), parts, labels, table);
  const std::unique_ptr<PropertyEstimator> estimator = make_overriding_estimator(*base, resolved);
  Result<PropertiesReport> report = estimate_properties(mesh, parts, completion, table, *estimator);
  EXPECT_TRUE(report.ok()) << report.status().to_string();
  if (report_out != nullptr) *report_out = *report;
  Result<SimulationAsset> asset = make_asset("bottle", mesh, parts, completion, *report, table);
  EXPECT_TRUE(asset.ok()) << asset.status().to_string();
  return *asset;
}

// The bottle's MJCF over a floor, released from rest tilted by `degrees` about
// X with its lowest point on the floor; after two seconds, the cosine of its
// tilt (1 upright, 0 on its side).
double upright_after_release(const SimulationAsset& asset, const std::string& dir, double degrees) {
  EXPECT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  std::string xml = test::read_file(dir + "/bottle.xml");
  const std::string body = "  <worldbody>\n";
  xml.insert(xml.find(body) + body.size(), "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\"/>\n");
  test::write_file(dir + "/tilted.xml", xml);
  char error[1000] = "";
  mjModel* m = mj_loadXML((dir + "/tilted.xml").c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  if (m == nullptr) return -1;
  mjData* d = mj_makeData(m);
  const double half = 0.5 * degrees * M_PI / 180.0;
  const Eigen::Quaterniond q(std::cos(half), std::sin(half), 0, 0);
  double lowest = 1e9;
  for (const AssetPart& part : asset.parts)
    for (const Eigen::Vector3f& v : part.closed.positions) lowest = std::min(lowest, (q * v.cast<double>()).z());
  const double qpos[7] = {0, 0, -lowest, q.w(), q.x(), q.y(), q.z()};
  std::copy(qpos, qpos + 7, d->qpos);
  const int steps = static_cast<int>(std::ceil(2.0 / m->opt.timestep));
  for (int i = 0; i < steps; ++i) mj_step(m, d);
  const double up = d->xmat[9 * 1 + 8];  // body 1's z axis, world z component
  mj_deleteData(d);
  mj_deleteModel(m);
  return up;
}

TEST(Exporters, WaterInABottleWeighsInMujocoAndKeepsItFromTipping) {
  const std::string empty = R"({"format": "g2p-overrides", "version": 1, "overrides": []})";
  const std::string half =
      R"({"format": "g2p-overrides", "version": 1, "overrides": [{"part": 0, "contents": {"fill": 0.5}}]})";
  PropertiesReport empty_report, half_report;
  const SimulationAsset bottle = bottle_asset(empty, &empty_report);
  const SimulationAsset filled = bottle_asset(half, &half_report);
  // The water: half the cavity (the cylinder less its 4 mm glass walls) at 1000 kg/m^3,
  // in the bottom quarter of the bottle.
  const PartReport& part = half_report.parts[0];
  ASSERT_EQ(part.properties.structure, Structure::kHollow);
  const double cavity = M_PI * 0.04 * 0.04 * 0.25 - empty_report.parts[0].mass.volume_m3;
  EXPECT_NEAR(part.contents.mass_kg, 0.5 * cavity * 1000.0, 0.01 * 0.5 * cavity * 1000.0);
  EXPECT_NEAR(part.contents.center_of_mass.z(), 0.25 * 0.25 * (cavity / (M_PI * 0.04 * 0.04 * 0.25)), 0.002);
  EXPECT_NEAR(part.mass.mass_kg, empty_report.parts[0].mass.mass_kg + part.contents.mass_kg, 1e-9);
  const std::string report = report_json(half_report, MaterialTable::paper_default());
  const nlohmann::json j = nlohmann::json::parse(report);
  EXPECT_NEAR(j["parts"][0]["contents"]["mass_kg"].get<double>(), part.contents.mass_kg, 1e-9);
  EXPECT_NEAR(j["parts"][0]["material_volume_m3"].get<double>(), empty_report.parts[0].mass.volume_m3, 1e-12);
  EXPECT_TRUE(nlohmann::json::parse(report_json(empty_report, MaterialTable::paper_default()))["parts"][0]["contents"]
                  .is_null());

  // MuJoCo compiles the filled bottle with the water's mass and its low centre of mass.
  const std::string dir = test::scratch_dir("ExportBottle");
  ASSERT_TRUE(write_asset(dir, filled, {"mjcf"}).ok());
  Result<EngineCheck> c = check_in_mujoco(dir + "/bottle.xml");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  expect_mujoco_agrees(*c, filled);
  EXPECT_LT(c->center_of_mass.z(), bottle.total.center_of_mass.z() - 0.02);

  // Tipping: a body tips over once its centre of mass passes over the base's
  // edge, at atan(r / z_com): about 18 degrees empty (centre of mass at mid
  // height) and 23 half full. Released at 20.5 degrees, the empty bottle falls
  // over and the half-full one rights itself; at 10 both stand.
  const double empty_critical = std::atan(0.04 / bottle.total.center_of_mass.z()) * 180.0 / M_PI;
  const double filled_critical = std::atan(0.04 / filled.total.center_of_mass.z()) * 180.0 / M_PI;
  ASSERT_LT(empty_critical, 19.5);
  ASSERT_GT(filled_critical, 21.5);
  EXPECT_LT(upright_after_release(bottle, test::scratch_dir("TipEmpty"), 20.5), 0.5);
  EXPECT_GT(upright_after_release(filled, test::scratch_dir("TipFilled"), 20.5), 0.99);
  EXPECT_GT(upright_after_release(bottle, test::scratch_dir("StandEmpty"), 10.0), 0.99);
}

// A 10 cm cube of one class through stages 5 and 6.
SimulationAsset cube_asset(int label) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry(Eigen::Vector3f::Zero(), Eigen::Vector3f::Constant(0.1f), p, t);
  const Mesh mesh = test::mesh_from_geometry(p, t);
  std::vector<Part> parts(1);
  parts[0].label = label;
  for (int f = 0; f < mesh.num_faces(); ++f) parts[0].faces.push_back(f);
  const MaterialTable& table = MaterialTable::paper_default();
  const Completion completion = *(*make_completer("partition"))->complete({&mesh, &parts, &table});
  const PropertiesReport report = *estimate_properties(mesh, parts, completion, table, **make_estimator("table"));
  Result<SimulationAsset> asset = make_asset("cube", mesh, parts, completion, report, table);
  EXPECT_TRUE(asset.ok()) << asset.status().to_string();
  return *asset;
}

// How far the cube's MJCF slides in a second, from rest on a floor inclined by
// `degrees` (gravity tilted instead of the floor). The floor's own friction is
// nearly 0, so MuJoCo's contact (the larger of the two geoms') is the cube's.
double slide_on_incline(const SimulationAsset& asset, const std::string& dir, double degrees) {
  EXPECT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  std::string xml = test::read_file(dir + "/cube.xml");
  const std::string body = "  <worldbody>\n";
  xml.insert(xml.find(body) + body.size(),
             "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" friction=\"0.0001 0 0\"/>\n");
  test::write_file(dir + "/incline.xml", xml);
  char error[1000] = "";
  mjModel* m = mj_loadXML((dir + "/incline.xml").c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  if (m == nullptr) return -1;
  const double theta = degrees * M_PI / 180.0;
  m->opt.gravity[0] = 0;
  m->opt.gravity[1] = 9.81 * std::sin(theta);
  m->opt.gravity[2] = -9.81 * std::cos(theta);
  mjData* d = mj_makeData(m);
  d->qpos[2] = 1e-4;
  mj_forward(m, d);
  const double start = d->xpos[3 * 1 + 1];
  const int steps = static_cast<int>(std::ceil(1.0 / m->opt.timestep));
  for (int i = 0; i < steps; ++i) mj_step(m, d);
  const double moved = d->xpos[3 * 1 + 1] - start;
  mj_deleteData(d);
  mj_deleteModel(m);
  return moved;
}

// The table's friction reaches the engine: each class's cube holds on an
// incline 4 degrees below its friction angle atan(mu) and slides 4 above it,
// so steel (mu 0.43, 23 degrees) slides where rubber (0.75, 37) holds. MuJoCo's
// soft contacts let a held body creep (5 to 9 mm in the second here); a slide
// accelerates, about 0.4 m in the second.
TEST(Exporters, EachClassHoldsBelowItsFrictionAngleAndSlidesAbove) {
  const MaterialTable& table = MaterialTable::paper_default();
  const int rubber = static_cast<int>(PaperClass::kRubber);
  std::map<int, SimulationAsset> cubes;
  for (const int label : {kMetal, rubber}) {
    const SimulationAsset& cube = cubes[label] = cube_asset(label);
    const double mu = table[label].friction_dynamic;
    const double angle = std::atan(mu) * 180.0 / M_PI;
    const std::string name = table[label].name;
    EXPECT_LT(std::abs(slide_on_incline(cube, test::scratch_dir("Hold" + name), angle - 4.0)), 0.02) << name;
    EXPECT_GT(slide_on_incline(cube, test::scratch_dir("Slide" + name), angle + 4.0), 0.1) << name;
  }
  // Between the two angles, the same slope tells the materials apart.
  EXPECT_GT(slide_on_incline(cubes[kMetal], test::scratch_dir("SlideMetal30"), 30.0), 0.1);
  EXPECT_LT(std::abs(slide_on_incline(cubes[rubber], test::scratch_dir("HoldRubber30"), 30.0)), 0.02);
}

TEST(Exporters, UrdfdomAndCheckUrdfReadTheUrdf) {
  const SimulationAsset asset = hammer_asset(kMetal);
  const std::string dir = test::scratch_dir("ExportUrdf");
  ASSERT_TRUE(write_asset(dir, asset, {"urdf"}).ok());
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(test::read_file(dir + "/hammer.urdf"));
  ASSERT_NE(model, nullptr);
  auto link = model->getLink("hammer");
  ASSERT_NE(link, nullptr);
  ASSERT_NE(link->inertial, nullptr);
  // The inertial is written with 9 significant digits (urdfdom alone writes 6).
  expect_relative(link->inertial->mass, asset.total.mass_kg, 1e-8, "URDF mass");
  expect_relative(link->inertial->ixx, asset.total.inertia(0, 0), 1e-8, "URDF ixx");
  expect_relative(link->inertial->iyz, asset.total.inertia(1, 2), 1e-8, "URDF iyz");
  EXPECT_EQ(link->visual_array.size(), asset.parts.size());
  std::size_t hulls = 0;
  for (const AssetPart& p : asset.parts) hulls += p.collision.hulls.size();
  EXPECT_GE(hulls, asset.parts.size());
  EXPECT_EQ(link->collision_array.size(), hulls);  // one collision element per convex hull
  for (const auto& c : link->collision_array) {
    auto mesh = std::dynamic_pointer_cast<urdf::Mesh>(c->geometry);
    ASSERT_NE(mesh, nullptr);
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + mesh->filename)) << mesh->filename;
  }
  for (const auto& v : link->visual_array) {
    auto mesh = std::dynamic_pointer_cast<urdf::Mesh>(v->geometry);
    ASSERT_NE(mesh, nullptr);
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + mesh->filename)) << mesh->filename;
  }
  if (std::filesystem::exists("/usr/bin/check_urdf"))
    EXPECT_EQ(std::system(("/usr/bin/check_urdf " + dir + "/hammer.urdf > /dev/null").c_str()), 0);

  // MuJoCo's URDF importer finds the meshes in meshes/ and compiles the link
  // with libg2p's mass properties.
  char error[1000] = "";
  mjModel* m = mj_loadXML((dir + "/hammer.urdf").c_str(), nullptr, error, sizeof error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_EQ(m->ngeom, static_cast<int>(hulls));
  expect_relative(m->body_mass[1], asset.total.mass_kg, 1e-6, "MuJoCo mass from the URDF");
  mj_deleteModel(m);
}

// A thin plate's principal moments sit at the triangle inequality's edge
// (A + B = C); six digits could round them past it and MuJoCo would refuse the
// URDF, nine keep them.
TEST(Exporters, AThinPlatesUrdfInertiaKeepsItsTriangleInequality) {
  SimulationAsset plate = hammer_asset(kMetal);
  plate.name = "plate";
  const double m = 0.4, a = 1.0, b = 0.2, c = 0.0002;  // a 1 x 0.2 m sheet 0.2 mm thick
  plate.total.mass_kg = m;
  plate.total.center_of_mass = Eigen::Vector3d(0.123456789, 0, 0.001);
  plate.total.inertia =
      Eigen::Vector3d(m * (b * b + c * c) / 12, m * (a * a + c * c) / 12, m * (a * a + b * b) / 12).asDiagonal();
  const std::string dir = test::scratch_dir("ExportThinUrdf");
  ASSERT_TRUE(write_asset(dir, plate, {"urdf"}).ok());
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(test::read_file(dir + "/plate.urdf"));
  ASSERT_NE(model, nullptr);
  const urdf::InertialSharedPtr in = model->getLink("plate")->inertial;
  EXPECT_GE(in->ixx + in->iyy, in->izz);
  EXPECT_NEAR(in->origin.position.x, 0.123456789, 1e-9);
  char error[1000] = "";
  mjModel* mj = mj_loadXML((dir + "/plate.urdf").c_str(), nullptr, error, sizeof error);
  ASSERT_NE(mj, nullptr) << error;
  mj_deleteModel(mj);
}

#ifdef G2P_TEST_WITH_SDFORMAT
TEST(Exporters, LibsdformatLoadsTheSdf) {
  // libsdformat (what Gazebo parses SDF with) reads the written file without
  // an error, with the same mass, a visual per part and a collision per hull.
  const SimulationAsset asset = hammer_asset(kMetal);
  const std::string dir = test::scratch_dir("ExportSdformat");
  ASSERT_TRUE(write_asset(dir, asset, {"sdf"}).ok());
  sdf::Root root;
  const sdf::Errors errors = root.Load(dir + "/hammer.sdf");
  std::string all;
  for (const sdf::Error& e : errors) all += e.Message() + "\n";
  ASSERT_TRUE(errors.empty()) << all;
  ASSERT_NE(root.Model(), nullptr);
  const sdf::Link* link = root.Model()->LinkByIndex(0);
  ASSERT_NE(link, nullptr);
  expect_relative(link->Inertial().MassMatrix().Mass(), asset.total.mass_kg, 1e-6, "libsdformat mass");
  std::size_t hulls = 0;
  for (const AssetPart& p : asset.parts) hulls += p.collision.hulls.size();
  EXPECT_EQ(link->CollisionCount(), hulls);
  EXPECT_EQ(link->VisualCount(), asset.parts.size());
}
#endif

TEST(Exporters, SdfIsWellFormedWithTheSameInertial) {
  const SimulationAsset asset = hammer_asset(kMetal);
  TiXmlDocument doc;
  doc.Parse(sdf_text(asset).c_str());
  ASSERT_FALSE(doc.Error()) << doc.ErrorDesc();
  TiXmlElement* sdf = doc.FirstChildElement("sdf");
  ASSERT_NE(sdf, nullptr);
  EXPECT_STREQ(sdf->Attribute("version"), "1.9");
  TiXmlElement* link = sdf->FirstChildElement("model")->FirstChildElement("link");
  ASSERT_NE(link, nullptr);
  expect_relative(std::atof(link->FirstChildElement("inertial")->FirstChildElement("mass")->GetText()),
                  asset.total.mass_kg, 1e-6, "SDF mass");
  int collisions = 0;
  for (TiXmlElement* c = link->FirstChildElement("collision"); c; c = c->NextSiblingElement("collision")) ++collisions;
  std::size_t hulls = 0;
  for (const AssetPart& p : asset.parts) hulls += p.collision.hulls.size();
  EXPECT_EQ(collisions, static_cast<int>(hulls));
}

// The hammer's GLB in a scratch folder of its own; "" if writing failed.
std::string hammer_glb(const std::string& scratch, Model& model, std::vector<Part>& parts, SimulationAsset& asset) {
  asset = hammer_asset(kMetal, &model, &parts);
  const std::string path = test::scratch_dir(scratch) + "/hammer.glb";
  const Status s = write_glb(path, model, parts, asset);
  EXPECT_TRUE(s.ok()) << s.to_string();
  return s.ok() ? path : std::string();
}

TEST(Exporters, GlbKeepsTheLookAndCarriesTheProperties) {
  Model model;
  std::vector<Part> parts;
  SimulationAsset asset;
  const std::string path = hammer_glb("ExportGlb", model, parts, asset);
  ASSERT_FALSE(path.empty());
  // libg2p's own strict glTF import reads it back as a viewer draws it: the
  // input's faces and materials in the same place, and no hull (hull nodes
  // carry no mesh, only a physics shape).
  Result<Model> back = load_model(path);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  int hulls = 0;
  for (const AssetPart& p : asset.parts) hulls += static_cast<int>(p.collision.hulls.size());
  EXPECT_EQ(back->mesh.num_faces(), model.mesh.num_faces());
  ASSERT_EQ(back->materials.size(), model.materials.size());
  EXPECT_EQ(back->materials[0].name, model.materials[0].name);
  EXPECT_FLOAT_EQ(back->materials[0].metallic, model.materials[0].metallic);
  const Eigen::AlignedBox3d a = bounds(model.mesh), b = bounds(back->mesh);
  EXPECT_LT((a.min() - b.min()).norm(), 1e-5);
  EXPECT_LT((a.max() - b.max()).norm(), 1e-5);
  // The JSON chunk: properties in the nodes' extras, in glTF's +Y-up frame.
  const std::string bytes = test::read_file(path);
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  const nlohmann::json doc = nlohmann::json::parse(bytes.substr(20, json_length));
  const nlohmann::json& root = doc["nodes"][0]["extras"]["g2p"];
  EXPECT_NEAR(root["mass_kg"].get<double>(), asset.total.mass_kg, 1e-9);
  EXPECT_NEAR(root["center_of_mass_m"][1].get<double>(), asset.total.center_of_mass.z(), 1e-9);  // z up -> y up
  int parts_with_density = 0, collision_nodes = 0;
  for (const auto& n : doc["nodes"]) {
    if (!n.contains("extras")) continue;
    const auto& g = n["extras"]["g2p"];
    parts_with_density += g.contains("density_kg_m3");
    collision_nodes += g.value("collision", false);
  }
  EXPECT_EQ(parts_with_density, 2);
  EXPECT_EQ(collision_nodes, hulls);

  // OMI_physics_body and OMI_physics_shape: the body's motion on the root, a
  // convex shape per hull, a collider per hull node.
  const nlohmann::json& motion = doc["nodes"][0]["extensions"]["OMI_physics_body"]["motion"];
  EXPECT_EQ(motion["type"], "dynamic");
  EXPECT_NEAR(motion["mass"].get<double>(), asset.total.mass_kg, 1e-9);
  EXPECT_NEAR(motion["centerOfMass"][1].get<double>(), asset.total.center_of_mass.z(), 1e-9);
  // Diagonal and orientation give back the tensor in glTF's axes (the extras').
  const Eigen::Quaterniond q(
      motion["inertiaOrientation"][3].get<double>(), motion["inertiaOrientation"][0].get<double>(),
      motion["inertiaOrientation"][1].get<double>(), motion["inertiaOrientation"][2].get<double>());
  const Eigen::Vector3d diagonal(motion["inertiaDiagonal"][0].get<double>(), motion["inertiaDiagonal"][1].get<double>(),
                                 motion["inertiaDiagonal"][2].get<double>());
  const Eigen::Matrix3d tensor = q.toRotationMatrix() * diagonal.asDiagonal() * q.toRotationMatrix().transpose();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(tensor(i, j), root["inertia_kg_m2"][i][j].get<double>(), 1e-9 * diagonal.maxCoeff()) << i << j;
  const nlohmann::json& shapes = doc["extensions"]["OMI_physics_shape"]["shapes"];
  ASSERT_EQ(static_cast<int>(shapes.size()), hulls);
  int colliders = 0;
  for (const auto& n : doc["nodes"]) {
    if (!n.contains("extensions")) continue;
    if (!n["extensions"]["OMI_physics_body"].contains("collider")) continue;
    ++colliders;
    EXPECT_FALSE(n.contains("mesh")) << n.dump();
    const nlohmann::json& shape = shapes[n["extensions"]["OMI_physics_body"]["collider"]["shape"].get<std::size_t>()];
    EXPECT_EQ(shape["type"], "convex");
    EXPECT_EQ(shape["convex"]["mesh"], n["extras"]["g2p"]["mesh"]);
    EXPECT_EQ(doc["meshes"][shape["convex"]["mesh"].get<std::size_t>()]["name"], n["name"]);
  }
  EXPECT_EQ(colliders, hulls);
  EXPECT_NE(std::find(doc["extensionsUsed"].begin(), doc["extensionsUsed"].end(), "OMI_physics_shape"),
            doc["extensionsUsed"].end());
}

TEST(Exporters, KhronosValidatorFindsNoErrorInTheGlb) {
  Model model;
  std::vector<Part> parts;
  SimulationAsset asset;
  const std::string path = hammer_glb("ExportGlbKhronos", model, parts, asset);
  ASSERT_FALSE(path.empty());
  const test::ValidatorRun v = test::run_gltf_validator(path);
  if (!v.available) GTEST_SKIP() << "node or the npm gltf-validator is missing: run scripts/install-deps.sh";
  EXPECT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  EXPECT_NE(v.run.out.find(": 0 errors, 0 warnings"), std::string::npos) << v.run.out;
}

TEST(Exporters, GlbWritesVertexColoursAsColor0) {
  SimulationAsset asset;
  Model model;
  std::vector<Part> parts;
  asset = hammer_asset(kMetal, &model, &parts);
  // A colour that varies with height and is never white.
  auto colour_at = [](const Eigen::Vector3f& p) { return Eigen::Vector4f(0.2f + p.z(), 0.3f, 0.9f, 1.f); };
  for (const Eigen::Vector3f& p : model.mesh.positions) model.mesh.colors.push_back(colour_at(p));
  const std::string path = test::scratch_dir("ExportGlbColours") + "/hammer.glb";
  ASSERT_TRUE(write_glb(path, model, parts, asset).ok());

  // Part primitives carry COLOR_0 (VEC4 float, one per vertex); hull primitives do not.
  const std::string bytes = test::read_file(path);
  std::uint32_t json_length = 0;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  const nlohmann::json doc = nlohmann::json::parse(bytes.substr(20, json_length));
  int coloured = 0;
  for (const auto& mesh : doc["meshes"])
    for (const auto& prim : mesh["primitives"]) {
      if (!prim["attributes"].contains("COLOR_0")) continue;
      ++coloured;
      const auto& a = doc["accessors"][prim["attributes"]["COLOR_0"].get<int>()];
      EXPECT_EQ(a["type"], "VEC4");
      EXPECT_EQ(a["componentType"], 5126);
      EXPECT_EQ(a["count"], doc["accessors"][prim["attributes"]["POSITION"].get<int>()]["count"]);
    }
  EXPECT_EQ(coloured, 2);  // the head's and the handle's

  // Read back (linear glTF colours, unchanged): each vertex has its colour, the hulls' are white.
  Result<Model> back = load_model(path);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_TRUE(back->mesh.has_colors());
  int matched = 0;
  for (int v = 0; v < back->mesh.num_vertices(); ++v) {
    const Eigen::Vector4f& c = back->mesh.colors[static_cast<std::size_t>(v)];
    if (c.isOnes()) continue;
    ++matched;
    EXPECT_TRUE(c.isApprox(colour_at(back->mesh.positions[static_cast<std::size_t>(v)]), 1e-4f))
        << "vertex " << v << ": " << c.transpose();
  }
  EXPECT_GE(matched, 16);  // at least the head box's corners
  const test::ValidatorRun validator = test::run_gltf_validator(path);
  if (validator.available)
    EXPECT_NE(validator.run.out.find(": 0 errors, 0 warnings"), std::string::npos) << validator.run.out;
}

// A body of 64 small convex pieces lying flat touches the floor at more points
// than MuJoCo 2.2's default contact buffer (nconmax 100) holds; the drop check
// says that contacts were dropped instead of reporting a clean rest.
TEST(Exporters, TheDropCheckReportsWhenMujocosContactBufferOverflows) {
  const std::string dir = test::scratch_dir("ExportContactFull");
  std::string geoms;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j)
      geoms += "      <geom class=\"g2p_collision\" mesh=\"tile\" pos=\"" + std::to_string(0.03 * i) + " " +
               std::to_string(0.03 * j) + " 0\"/>\n";
  test::write_file(dir + "/tiles.xml",
                   "<mujoco model=\"tiles\">\n  <compiler meshdir=\"meshes\"/>\n  <default>\n    <default "
                   "class=\"g2p_collision\"><geom type=\"mesh\" group=\"3\" contype=\"1\" conaffinity=\"1\"/>"
                   "</default>\n  </default>\n  <asset>\n    <mesh name=\"tile\" vertex=\"0 0 0  0.02 0 0  0 0.02 0  "
                   "0.02 0.02 0  0 0 0.01  0.02 0 0.01  0 0.02 0.01  0.02 0.02 0.01\"/>\n  </asset>\n  <worldbody>\n"
                   "    <body name=\"tiles\">\n      <freejoint/>\n" +
                       geoms + "    </body>\n  </worldbody>\n</mujoco>\n");
  const auto log_size = [] {
    std::error_code ec;
    const auto n = std::filesystem::file_size("MUJOCO_LOG.TXT", ec);
    return ec ? std::uintmax_t{0} : n;
  };
  const std::uintmax_t log_before = log_size();
  Result<EngineCheck> c = check_in_mujoco(dir + "/tiles.xml", 0.05, 1.0);
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  ASSERT_TRUE(c->dropped);
  ASSERT_FALSE(c->warnings.empty());
  EXPECT_NE(c->warnings.front().find("contact buffer was full"), std::string::npos) << c->warnings.front();
  // MuJoCo's own log file in the working directory did not grow.
  EXPECT_EQ(log_size(), log_before);
  // The hammer's drop is clean.
  const SimulationAsset hammer = hammer_asset(kMetal);
  const std::string hdir = test::scratch_dir("ExportCleanDrop");
  ASSERT_TRUE(write_asset(hdir, hammer, {"mjcf"}).ok());
  Result<EngineCheck> clean = check_in_mujoco(hdir + "/hammer.xml");
  ASSERT_TRUE(clean.ok()) << clean.status().to_string();
  EXPECT_TRUE(clean->warnings.empty()) << clean->warnings.front();
}

TEST(Exporters, BadInputIsRefused) {
  const SimulationAsset asset = hammer_asset(kMetal);
  EXPECT_EQ(write_asset(test::scratch_dir("ExportBad"), asset, {"fbx"}).code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(check_in_mujoco(test::scratch_dir("ExportBad2") + "/missing.xml").ok());
  const std::string dir = test::scratch_dir("ExportBad3");
  test::write_file(dir + "/broken.xml",
                   "<mujoco><worldbody><body><geom type=\"mesh\" mesh=\"nope\"/></body></worldbody></mujoco>");
  Result<EngineCheck> c = check_in_mujoco(dir + "/broken.xml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("MuJoCo"), std::string::npos) << c.status().message();
}

// Every shared asset, labelled with its ground truth, exports an MJCF that
// MuJoCo compiles with libg2p's mass properties and drops without blowing up.
class ExportAssets : public testing::TestWithParam<const char*> {};

TEST_P(ExportAssets, MujocoAgreesAndTheDropSettles) {
  const std::string name = GetParam();
  const test::TruthExport e = test::export_shared_asset(name);
  // A part whose closed volume passed its checks has a mass (the checks and
  // the mass properties agree on what encloses a volume).
  for (std::size_t i = 0; i < e.parts.size(); ++i)
    if (e.completion.parts[i].ok) EXPECT_GT(e.report.parts[i].mass.mass_kg, 0.0) << name << " part " << i;
  const SimulationAsset& asset = e.asset;
  const std::string dir = test::scratch_dir("ExportAsset" + name);
  ASSERT_TRUE(write_asset(dir, asset, {"mjcf", "urdf", "sdf"}).ok());
  Result<EngineCheck> c = check_in_mujoco(dir + "/" + asset.name + ".xml");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  expect_mujoco_agrees(*c, asset);
  EXPECT_TRUE(c->finite);
  EXPECT_GT(c->resting_lowest_m, -0.01);
  EXPECT_LT(c->final_speed_m_s, 0.1);
  if (std::filesystem::exists("/usr/bin/check_urdf"))
    EXPECT_EQ(std::system(("/usr/bin/check_urdf " + dir + "/" + asset.name + ".urdf > /dev/null").c_str()), 0);
}

INSTANTIATE_TEST_SUITE_P(SharedAssets, ExportAssets,
                         testing::Values("SheenChair", "GlamVelvetSofa", "GlassHurricaneCandleHolder", "WaterBottle",
                                         "Avocado"));

}  // namespace
}  // namespace g2p
