// `g2p export` and `g2p validate` as a user runs them.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using test::quote;
using test::run_tool;
using test::ToolRun;

TEST(ToolExport, WritesAssetsThatValidateInMujoco) {
  const std::string dir = test::scratch_dir("ToolExport");
  test::write_file(dir + "/labels.json", R"({"models": {"hammer": {"labels": {"0": "Wood", "1": "Metal"}}}})");
  ToolRun r = run_tool("export " + quote(test::source_path("examples/data/hammer.obj")) + " --truth " +
                       quote(dir + "/labels.json") + " -o " + quote(dir + "/out"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  for (const char* f :
       {"hammer.xml", "hammer.urdf", "hammer.sdf", "hammer.glb", "report.json", "meshes/part_1_Metal.stl"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f)) << f;
  // Relocatable: validate a moved copy.
  std::filesystem::rename(dir + "/out", dir + "/moved");
  r = run_tool("validate " + quote(dir + "/moved"));
  if (r.err.find("without MuJoCo") != std::string::npos) GTEST_SKIP() << "libg2p built without MuJoCo";
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("MuJoCo"), std::string::npos) << r.out;
}

TEST(ToolExport, BadInputFailsWithAMessage) {
  const std::string dir = test::scratch_dir("ToolExportBad");
  ToolRun r = run_tool("validate " + quote(dir));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no MJCF"), std::string::npos) << r.err;
  r = run_tool("export " + quote(test::source_path("examples/data/hammer.obj")) + " -o " + quote(dir + "/x") +
               " --format gltf");
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace g2p
