// Contacts scaled to the object (#50): cubes from 1 cm to 5 m dropped from
// their own height onto a plane in MuJoCo sink a small share of their side
// and come to rest; a 2 cm ball dropped onto a sofa's fabric seat stays on it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "g2p/complete.h"
#include "g2p/export.h"
#include "g2p/io.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/segment.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// A solid box of `size_m` (one part, `material`, 1000 kg/m^3) that collides
// as itself, written as MJCF with `options`.
std::string box_mjcf(const Eigen::Vector3f& size_m, const std::string& material, const ExportOptions& options,
                     const std::string& dir) {
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry(Eigen::Vector3f::Zero(), size_m, p, t);
  const Mesh cube = test::mesh_from_geometry(p, t);
  SimulationAsset asset;
  asset.name = "cube";
  AssetPart part;
  part.part = 0;
  part.name = "part_0_" + material;
  part.material = material;
  part.closed = part.visual = cube;
  part.collision.hulls = {cube};
  part.properties.density_kg_m3 = 1000.0;
  part.mass = *solid_mass_properties(cube, 1000.0);
  asset.parts.push_back(part);
  asset.total = combine({part.mass});
  EXPECT_TRUE(write_asset(dir, asset, {"mjcf"}, options).ok());
  return dir + "/cube.xml";
}

std::string cube_mjcf(double side_m, const std::string& material, const ExportOptions& options,
                      const std::string& dir) {
  return box_mjcf(Eigen::Vector3f::Constant(static_cast<float>(side_m)), material, options, dir);
}

// Dropped from its own height for `seconds`: how deep it sank at most, how
// deep it rests and how fast it moves at the end.
EngineCheck drop(const Eigen::Vector3f& size_m, const ExportOptions& options, const std::string& name,
                 double seconds = 1.5) {
  Result<EngineCheck> c =
      check_in_mujoco(box_mjcf(size_m, "Plastic", options, test::scratch_dir(name)), size_m.z(), seconds);
  EXPECT_TRUE(c.ok()) << c.status().to_string();
  return c.ok() ? *c : EngineCheck{};
}
EngineCheck drop(double side_m, const ExportOptions& options, const std::string& name) {
  return drop(Eigen::Vector3f::Constant(static_cast<float>(side_m)), options, name);
}

TEST(ContactScale, ObjectsFrom1cmTo5mLandWithoutSinking) {
  for (const double side : {0.01, 0.1, 1.0, 5.0}) {
    char name[32];
    std::snprintf(name, sizeof name, "ContactScaleCube%gm", side);
    const EngineCheck c = drop(side, ExportOptions{}, name);
    ASSERT_TRUE(c.dropped && c.finite) << side;
    EXPECT_TRUE(c.warnings.empty()) << side;
    // Sinks at most 5 % of its side on impact (the rule aims at 2 %), rests
    // less than 1 % deep and still.
    EXPECT_GT(c.lowest_point_m, -0.05 * side) << side << " m cube";
    EXPECT_GT(c.resting_lowest_m, -0.01 * side) << side << " m cube";
    EXPECT_LT(c.resting_lowest_m, 0.01 * side) << side << " m cube";
    EXPECT_LT(c.final_speed_m_s, 0.01) << side << " m cube";
    std::printf("[ scale   ] %g m cube: sank %.3g m (%.2f %% of its side), rests %.3g m, %.3g m/s\n", side,
                -c.lowest_point_m, -100.0 * c.lowest_point_m / side, c.resting_lowest_m, c.final_speed_m_s);
  }
  // A plank lying flat (1 m x 10 cm x 2 cm) and a 2 cm post standing 50 cm
  // tall, which lands on its end (the time constant held at 0.5 ms) and
  // topples: each sinks less than 5 % of its 2 cm.
  for (const Eigen::Vector3f& size : {Eigen::Vector3f(1.0f, 0.1f, 0.02f), Eigen::Vector3f(0.02f, 0.02f, 0.5f)}) {
    const EngineCheck c = drop(size, ExportOptions{}, "ContactScaleBox" + std::to_string(size.z()), 3.0);
    ASSERT_TRUE(c.dropped && c.finite);
    EXPECT_GT(c.lowest_point_m, -0.05 * 0.02) << size.transpose();
    EXPECT_GT(c.resting_lowest_m, -0.01 * 0.02) << size.transpose();
    EXPECT_LT(c.final_speed_m_s, 0.01) << size.transpose();
    std::printf("[ scale   ] %g x %g x %g m box: sank %.3g m (%.2f %% of 2 cm), rests %.3g m, %.3g m/s\n", size.x(),
                size.y(), size.z(), -c.lowest_point_m, -100.0 * c.lowest_point_m / 0.02, c.resting_lowest_m,
                c.final_speed_m_s);
  }
  // MuJoCo's defaults (no scaling): the 1 cm cube sinks a third of its side.
  ExportOptions unscaled;
  unscaled.scale_contacts = false;
  const EngineCheck c = drop(0.01, unscaled, "ContactScaleCubeUnscaled");
  EXPECT_LT(c.lowest_point_m, -0.2 * 0.01) << c.lowest_point_m;
  std::printf("[ default ] 0.01 m cube: sank %.3g m, rests %.3g m\n", -c.lowest_point_m, c.resting_lowest_m);
}

TEST(ContactScale, TheRuleAndItsOverridesReachTheMjcf) {
  const std::string dir = test::scratch_dir("ContactScaleRule");
  const std::string small = test::read_file(cube_mjcf(0.01, "Fabric", ExportOptions{}, dir));
  // 1 cm cube from 1 cm: e * 0.02 * 0.01 / (sqrt(2 g 0.01) sqrt(0.95)) = 1.26 ms, a 0.63 ms step.
  EXPECT_NE(small.find("timestep=\"0.00062"), std::string::npos) << small;
  EXPECT_NE(small.find("solref=\"0.00125"), std::string::npos) << small;
  EXPECT_NE(small.find("condim=\"6\""), std::string::npos);  // fabric: torsional and rolling friction
  EXPECT_NE(small.find("friction=\"0.5 0.02 0.02\""), std::string::npos) << small;  // a cushion's 2 cm lever
  // Friction as hard as the contact is soft (#62: balls stop on sloping seats).
  EXPECT_NE(small.find("cone=\"elliptic\" impratio=\"10\""), std::string::npos) << small;
  const std::string tyre =
      test::read_file(cube_mjcf(0.01, "Rubber", ExportOptions{}, test::scratch_dir("ContactScaleRubber")));
  EXPECT_NE(tyre.find("friction=\"0.5 0.02 0.005\""), std::string::npos) << tyre;  // rubber rolls: 5 mm
  ExportOptions fixed;
  fixed.timestep_s = 0.001;
  const std::string overridden = test::read_file(cube_mjcf(0.01, "Fabric", fixed, dir));
  EXPECT_NE(overridden.find("timestep=\"0.001\""), std::string::npos);
  // A 5 m cube keeps MuJoCo's own time constant and step.
  const std::string big = test::read_file(cube_mjcf(5.0, "Plastic", ExportOptions{}, dir));
  EXPECT_NE(big.find("timestep=\"0.002\""), std::string::npos);
  EXPECT_NE(big.find("solref=\"0.02 1\""), std::string::npos);
  EXPECT_EQ(big.find("condim"), std::string::npos);  // plastic: sliding friction only
  ExportOptions off;
  off.scale_contacts = false;
  const std::string plain = test::read_file(cube_mjcf(0.01, "Fabric", off, dir));
  EXPECT_EQ(plain.find("timestep"), std::string::npos);
  EXPECT_NE(plain.find("solref=\"0.02 1\""), std::string::npos);
  ExportOptions bad;
  bad.contact_sink = 0;
  EXPECT_EQ(write_asset(dir, SimulationAsset{}, {"mjcf"}, bad).code(), StatusCode::kInvalidArgument);
}

// GlamVelvetSofa labelled with its ground truth, as the pipeline would
// export it; a 2 cm ball dropped over the middle of each seat cushion stays
// on the seat (before #50 the balls rolled down the domed cushions).
TEST(ContactScale, BallStaysOnTheSofasSeat) {
  const std::string name = "GlamVelvetSofa";
  const Model model = *load_model(test::asset_path(name));
  const MaterialTable& table = MaterialTable::paper_default();
  const std::vector<int> by_material = *material_labels_from_json(test::read_file(test::labels_json_path()), name,
                                                                  table, static_cast<int>(model.materials.size()));
  std::vector<int> labels;
  for (const FaceSource& f : model.mesh.face_source) {
    const int l = by_material[static_cast<std::size_t>(f.material)];
    labels.push_back(l == kUnknownLabel ? static_cast<int>(PaperClass::kOther) : l);
  }
  std::vector<int> face_part;
  const std::vector<Part> parts = partition(model.mesh, *build_face_graph(model.mesh), labels, face_part);
  const Completion completion = *(*make_completer("partition"))->complete({&model.mesh, &parts, &table});
  const PropertiesReport report = *estimate_properties(model.mesh, parts, completion, table, **make_estimator("table"));
  const SimulationAsset asset = *make_asset(name, model.mesh, parts, completion, report, table);
  const std::string dir = test::scratch_dir("ContactScaleSofa");
  ASSERT_TRUE(write_asset(dir, asset, {"mjcf"}).ok());
  ContactCheckOptions o;
  o.grid = 0;
  o.points = {{-0.6, 0.1}, {0.6, 0.1}};
  o.places = false;
  o.ball_radius_m = 0.01;
  o.seconds = 2.0;
  Result<ContactCheck> c = check_contacts_in_mujoco(dir + "/" + asset.name + ".xml", o);
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  for (const BallProbe& b : c->balls) {
    EXPECT_TRUE(b.on_object) << b.start.transpose();
    EXPECT_GT(b.height_above_floor_m, 0.4) << b.start.transpose();
    EXPECT_LT((b.rest.head<2>() - b.start).norm(), 0.15) << b.start.transpose() << " -> " << b.rest.transpose();
  }
}

}  // namespace
}  // namespace g2p
