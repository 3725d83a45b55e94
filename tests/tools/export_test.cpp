// `g2p export` and `g2p validate` as a user runs them.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using test::quote;
using test::run_tool;
using test::ToolRun;

// `g2p export` of the bundled hammer labelled by its materials into DIR/out.
ToolRun export_hammer(const std::string& dir, const std::string& flags = "") {
  test::write_file(dir + "/labels.json", R"({"models": {"hammer": {"labels": {"0": "Wood", "1": "Metal"}}}})");
  return run_tool("export " + quote(test::source_path("examples/data/hammer.obj")) + " --truth " +
                  quote(dir + "/labels.json") + flags + " -o " + quote(dir + "/out"));
}

TEST(ToolExport, WritesAssetsThatValidateInMujoco) {
  const std::string dir = test::scratch_dir("ToolExport");
  ToolRun r = export_hammer(dir);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  for (const char* f : {"hammer.xml", "hammer.urdf", "hammer.sdf", "hammer.glb", "report.json",
                        "meshes/part_1_Metal_hull_0.obj", "meshes/part_1_Metal_visual.obj"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f)) << f;
  // Relocatable: validate a moved copy.
  std::filesystem::rename(dir + "/out", dir + "/moved");
  r = run_tool("validate " + quote(dir + "/moved"));
  if (r.err.find("without MuJoCo") != std::string::npos) GTEST_SKIP() << "libg2p built without MuJoCo";
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MuJoCo"), std::string::npos) << r.out;
  // A second MJCF beside the exported one (a user's copy with a floor, say) is
  // not picked at random: validate names both and stops.
  std::filesystem::copy_file(dir + "/moved/hammer.xml", dir + "/moved/hammer_floor.xml");
  r = run_tool("validate " + quote(dir + "/moved"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("several MJCF (.xml) files (hammer.xml, hammer_floor.xml)"), std::string::npos) << r.err;
}

TEST(ToolExport, StartsFromAPropertiesOutput) {
  const std::string dir = test::scratch_dir("ToolExportFromProperties");
  test::write_file(dir + "/labels.json", R"({"models": {"hammer": {"labels": {"0": "Wood", "1": "Metal"}}}})");
  ToolRun r = run_tool("properties " + quote(test::source_path("examples/data/hammer.obj")) + " --truth " +
                       quote(dir + "/labels.json") + " -o " + quote(dir + "/props"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = run_tool("export " + quote(dir + "/props") + " --format mjcf,urdf,sdf,glb -o " + quote(dir + "/assets"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  // The folder's closed parts and properties are used as they are: only decompose and export run.
  EXPECT_NE(r.out.find("decompose "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("complete "), std::string::npos) << "stage 5 ran again: " << r.out;
  EXPECT_EQ(r.out.find("properties "), std::string::npos) << "stage 6 ran again: " << r.out;
  for (const char* f : {"hammer.xml", "hammer.urdf", "hammer.sdf", "hammer.glb"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/assets/" + f)) << f;
  const auto mass = [](const std::string& report) {
    return nlohmann::json::parse(test::read_file(report))["object"]["mass_kg"].get<double>();
  };
  EXPECT_NEAR(mass(dir + "/assets/report.json"), mass(dir + "/props/report.json"), 1e-9);
  const nlohmann::json report = nlohmann::json::parse(test::read_file(dir + "/assets/report.json"));
  for (const auto& part : report["parts"]) {
    EXPECT_GE(part["geometry"]["collision"]["hulls"].get<int>(), 1);
    EXPECT_EQ(part["geometry"]["collision"]["backend"], "voxel-cut");
  }
  r = run_tool("validate " + quote(dir + "/assets"));
  if (r.err.find("without MuJoCo") != std::string::npos) GTEST_SKIP() << "libg2p built without MuJoCo";
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
}

TEST(ToolExport, BadInputFailsWithAMessage) {
  const std::string dir = test::scratch_dir("ToolExportBad");
  ToolRun r = run_tool("validate " + quote(dir));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no MJCF"), std::string::npos) << r.err;
  r = run_tool("export " + quote(test::source_path("examples/data/hammer.obj")) + " -o " + quote(dir + "/x") +
               " --format gltf");
  EXPECT_EQ(r.exit_code, 2);
  // A drop from below the plane or for NaN seconds once ran no steps and printed PASS.
  for (const std::string& flags : {"--drop-height -5", "--seconds nan", "--seconds 1e12", "--contact-seconds 0"}) {
    r = run_tool("validate " + quote(dir) + " " + flags);
    EXPECT_EQ(r.exit_code, 2) << flags;
    EXPECT_NE(r.err.find(flags.substr(0, flags.find(' ')) + ": takes a number in"), std::string::npos) << r.err;
  }
}

TEST(ToolValidate, ContactCheckDropsBallsAndWritesJson) {
  const std::string dir = test::scratch_dir("ToolValidateContact");
  ToolRun r = export_hammer(dir, " --format mjcf");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = run_tool("validate " + quote(dir + "/out") + " --contact --balls 2 --no-places --json " +
               quote(dir + "/contact.json"));
  if (r.err.find("without MuJoCo") != std::string::npos) GTEST_SKIP() << "libg2p built without MuJoCo";
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("4 balls"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/contact.json"));
  ASSERT_EQ(j["balls"].size(), 4u);
  for (const auto& b : j["balls"]) {
    EXPECT_GT(b["radius_m"].get<double>(), 0.0);
    EXPECT_TRUE(b["on_object"].get<bool>() || b["on_floor"].get<bool>()) << b;
  }
  EXPECT_TRUE(j["drop"]["object_above_plane"].get<bool>());

  EXPECT_TRUE(j["places"].empty()) << j["places"];
  r = run_tool("validate " + quote(dir + "/out") + " --contact --balls 0 --no-places");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--balls"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--no-places"), std::string::npos) << r.err;
  r = run_tool("validate " + quote(dir + "/missing"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no such folder"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace g2p
