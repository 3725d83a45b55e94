// The object's real size at import: --height, --longest-side, and the
// warning for meshes that look normalised, as image-to-3D generators write them.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "g2p/io.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// An OBJ box of the given sides (metres; +Y up in the file, as OBJ is read).
std::string box_obj(double x, double y_up, double z) {
  std::ostringstream s;
  for (int i = 0; i < 8; ++i)
    s << "v " << (i & 1 ? x : 0) << " " << (i & 2 ? y_up : 0) << " " << (i & 4 ? z : 0) << "\n";
  s << "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return s.str();
}

Result<Model> load_box(double x, double y_up, double z, const ImportOptions& options = {}) {
  const std::string text = box_obj(x, y_up, z);
  return load_model_from_memory(text.data(), text.size(), "obj", options);
}

TEST(RealSize, AUnitCubeLooksNormalisedAndTheWarningNamesTheFlags) {
  for (const double longest : {1.0, 0.995, 2.0}) {
    Result<Model> m = load_box(0.4, 0.6 * longest, longest);
    ASSERT_TRUE(m.ok()) << m.status().to_string();
    EXPECT_TRUE(m->info.looks_normalised) << longest;
    EXPECT_EQ(m->info.scale_source, "file");
    ASSERT_FALSE(m->info.warnings.empty());
    const std::string& w = m->info.warnings.back();
    EXPECT_NE(w.find("--height or --longest-side"), std::string::npos) << w;
    EXPECT_NE(w.find("looks normalised"), std::string::npos) << w;
  }
}

TEST(RealSize, RealObjectsAndGivenUnitsDoNotWarn) {
  // The shared assets and the hammer are real sizes (0.06 to 2.19 m).
  for (const char* name : {"Avocado", "GlamVelvetSofa", "WaterBottle"}) {
    ImportOptions o;
    o.load_textures = false;
    Result<Model> m = load_model(test::asset_path(name), o);
    ASSERT_TRUE(m.ok()) << m.status().to_string();
    EXPECT_FALSE(m->info.looks_normalised) << name;
  }
  Result<Model> hammer = load_model(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(hammer.ok());
  EXPECT_FALSE(hammer->info.looks_normalised);
  ImportOptions metres;
  metres.unit_scale = 1.0;  // a real 1 m object, said so with --unit m
  Result<Model> m = load_box(0.5, 0.5, 1.0, metres);
  ASSERT_TRUE(m.ok());
  EXPECT_FALSE(m->info.looks_normalised);
  EXPECT_EQ(m->info.scale_source, "unit");
}

TEST(RealSize, HeightScalesUniformlyAlongTheUpAxis) {
  ImportOptions o;
  o.height_m = 0.25;  // the file's +Y becomes +Z
  Result<Model> m = load_box(0.4, 1.0, 0.6, o);
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  const Eigen::Vector3d sides = bounds(m->mesh).sizes();
  EXPECT_NEAR(sides.z(), 0.25, 1e-6);
  EXPECT_NEAR(sides.x(), 0.1, 1e-6);   // 0.4 * 0.25
  EXPECT_NEAR(sides.y(), 0.15, 1e-6);  // 0.6 * 0.25
  EXPECT_DOUBLE_EQ(m->info.unit_scale_m, 0.25);
  const double column_length = m->info.file_to_model.col(0).head<3>().norm();
  EXPECT_NEAR(column_length, 0.25, 1e-12);
  EXPECT_EQ(m->info.scale_source, "height");
  EXPECT_FALSE(m->info.looks_normalised);
  EXPECT_EQ(object_size(*m).scale_source, "height");

  ImportOptions keep;  // the file's axes kept: height is along the file's up axis (+Y)
  keep.height_m = 0.5;
  keep.z_up = false;
  Result<Model> k = load_box(0.4, 1.0, 0.6, keep);
  ASSERT_TRUE(k.ok());
  EXPECT_NEAR(bounds(k->mesh).sizes().y(), 0.5, 1e-6);
}

TEST(RealSize, LongestSideScalesTheLongestSide) {
  ImportOptions o;
  o.longest_side_m = 0.3;
  Result<Model> m = load_box(2.0, 1.0, 0.5, o);
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  EXPECT_NEAR(bounds(m->mesh).sizes().maxCoeff(), 0.3, 1e-6);
  EXPECT_NEAR(bounds(m->mesh).sizes().minCoeff(), 0.075, 1e-6);
  EXPECT_EQ(m->info.scale_source, "longest-side");
  // A size fixes what the unit guard would refuse (a 20 km file).
  Result<Model> huge = load_box(20000.0, 100.0, 100.0, o);
  ASSERT_TRUE(huge.ok()) << huge.status().to_string();
  EXPECT_NEAR(bounds(huge->mesh).sizes().maxCoeff(), 0.3, 1e-6);
}

TEST(RealSize, ConflictingOrBadSizesAreRefusedNamingTheFlags) {
  struct Case {
    double unit, height, longest;
    const char* says;
  };
  for (const Case& c : {Case{0, 0.3, 0.4, "--height and --longest-side"}, Case{0.01, 0.3, 0, "--height and --unit"},
                        Case{0.01, 0, 0.3, "--longest-side and --unit"}, Case{0, -1, 0, "--height must be"},
                        Case{0, 0, std::nan(""), "--longest-side must be"}}) {
    ImportOptions o;
    o.unit_scale = c.unit;
    o.height_m = c.height;
    o.longest_side_m = c.longest;
    Result<Model> m = load_box(1, 1, 1, o);
    ASSERT_FALSE(m.ok()) << c.says;
    EXPECT_EQ(m.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(m.status().message().find(c.says), std::string::npos) << m.status().message();
  }
  // A flat model has no height to scale: the message offers --longest-side.
  const std::string flat = "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n";
  ImportOptions o;
  o.height_m = 0.5;
  Result<Model> m = load_model_from_memory(flat.data(), flat.size(), "obj", o);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("--longest-side"), std::string::npos) << m.status().message();
}

}  // namespace
}  // namespace g2p
