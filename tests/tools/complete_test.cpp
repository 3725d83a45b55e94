// `g2p complete` as a user runs it: from a project folder, from a model with
// its ground truth, and with bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/properties.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using test::quote;
using test::run_tool;
using test::ToolRun;

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

TEST(ToolComplete, FromAProjectFolder) {
  const std::string dir = test::scratch_dir("ToolCompleteProject");
  const std::string hammer = test::source_path("examples/data/hammer.obj");
  ToolRun p = run_tool("project " + quote(hammer) + " -o " + quote(dir + "/p") + " --resolution 256 --refiner smooth");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  ToolRun r = run_tool("complete " + quote(dir + "/p") + " --format obj,stl");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("closed"), std::string::npos) << r.out;
  const nlohmann::json j = read_json(dir + "/p/completed/completion.json");
  ASSERT_GE(j["parts"].size(), 1u);
  for (const auto& part : j["parts"]) {
    EXPECT_TRUE(part["ok"].get<bool>()) << part.dump();
    EXPECT_TRUE(part["checks"]["watertight"].get<bool>());
    for (const char* ext : {"obj", "stl"})
      EXPECT_TRUE(std::filesystem::exists(dir + "/p/completed/" + part["files"][ext].get<std::string>()));
  }
  EXPECT_NEAR(j["parts_volume_m3"].get<double>() / j["object_volume_m3"].get<double>(), 1.0, 0.02);
}

TEST(ToolComplete, FromAModelWithGroundTruth) {
  const std::string dir = test::scratch_dir("ToolCompleteTruth");
  test::write_file(dir + "/labels.json", R"({"models": {"hammer": {"labels": {"0": "Wood", "1": "Metal"}}}})");
  const std::string hammer = test::source_path("examples/data/hammer.obj");
  ToolRun r =
      run_tool("complete " + quote(hammer) + " --truth " + quote(dir + "/labels.json") + " -o " + quote(dir + "/out"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json j = read_json(dir + "/out/completed/completion.json");
  ASSERT_EQ(j["parts"].size(), 2u);
  std::vector<std::string> labels;
  for (const auto& part : j["parts"]) labels.push_back(part["label"]);
  std::sort(labels.begin(), labels.end());
  EXPECT_EQ(labels, (std::vector<std::string>{"Metal", "Wood"}));
  // The part meshes read back closed, and the metal head is where the head is (+Y up in the file: +Z here).
  for (const auto& part : j["parts"]) {
    ImportOptions io;
    io.z_up = false;
    io.unit_scale = 1.0;
    io.up_axis = UpAxis::kZ;
    Result<Model> m = load_model(dir + "/out/completed/" + part["files"]["obj"].get<std::string>(), io);
    ASSERT_TRUE(m.ok()) << m.status().to_string();
    const MassProperties mp = *solid_mass_properties(m->mesh, 1.0);
    EXPECT_NEAR(mp.volume_m3, part["checks"]["volume_m3"].get<double>(), 1e-6 * mp.volume_m3 + 1e-12);
    if (part["label"] == "Metal") EXPECT_GT(mp.center_of_mass.z(), 0.29);
    if (part["label"] == "Wood") EXPECT_LT(mp.center_of_mass.z(), 0.2);
  }
}

TEST(ToolComplete, BadInputFailsWithAMessage) {
  const std::string dir = test::scratch_dir("ToolCompleteBad");
  ToolRun r = run_tool("complete " + quote(dir));  // an empty folder
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  r = run_tool("complete " + hammer + " -o " + quote(dir + "/out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--truth"), std::string::npos) << r.err;
  r = run_tool("complete " + hammer + " --truth " + quote(dir + "/labels.json"));  // no -o for a file
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("-o OUT"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out"));
  r = run_tool("complete " + quote(dir) + " --format fbx");
  EXPECT_EQ(r.exit_code, 2);
  r = run_tool("complete " + quote(dir) + " --completer no-such");
  EXPECT_NE(r.exit_code, 0);
}

}  // namespace
}  // namespace g2p
