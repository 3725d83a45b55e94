// g2p render as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/io.h"
#include "g2p/render.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

TEST(ToolRender, WritesViewsCamerasAndContactSheet) {
  const std::string folder = test::scratch_dir("ToolRender.Writes") + "/out", out = folder + "/views";
  test::ToolRun r = test::run_tool("render " + test::quote(test::source_path("examples/data/hammer.obj")) + " -o " +
                                   test::quote(folder) + " --views 3 --resolution 48 --buffers");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("rendered 3 views of 104 triangles"), std::string::npos) << r.out;
  for (const char* f :
       {"view_00_rgb.png", "view_02_faceid.png", "view_01_depth.npy", "cameras.json", "contact_sheet.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out + "/" + f)) << f;
  Result<std::vector<Camera>> cams = cameras_from_json(test::read_file(out + "/cameras.json"));
  ASSERT_TRUE(cams.ok());
  EXPECT_EQ(cams->size(), 3u);
  EXPECT_EQ((*cams)[0].width, 48);
  // Some pixel of some view sees the hammer, and its face ID is a real face.
  Result<ImageI32> ids = decode_face_ids(*read_image(out + "/view_02_faceid.png"));
  ASSERT_TRUE(ids.ok());
  int hits = 0;
  for (std::size_t i = 0; i < ids->size(); ++i) {
    ASSERT_LT(ids->data()[i], 104);
    hits += ids->data()[i] >= 0;
  }
  EXPECT_GT(hits, 20);
  EXPECT_TRUE(std::filesystem::is_regular_file(folder + "/manifest.json"));
  // A rerun with fewer views replaces the folder whole (with --overwrite): no view of the first is left.
  EXPECT_EQ(test::run_tool("render " + test::quote(test::source_path("examples/data/hammer.obj")) + " -o " +
                           test::quote(folder) + " --views 1 --resolution 48")
                .exit_code,
            2);
  r = test::run_tool("render " + test::quote(test::source_path("examples/data/hammer.obj")) + " -o " +
                     test::quote(folder) + " --views 1 --resolution 48 --overwrite");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out + "/view_02_rgb.png"));
  EXPECT_FALSE(std::filesystem::exists(out + "/view_01_depth.npy"));
}

TEST(ToolRender, BenchmarkModePrintsThroughput) {
  test::ToolRun r = test::run_tool("render --benchmark --views 2 --resolution 32 " +
                                   test::quote(test::source_path("examples/data/hammer.obj")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("face-id pass"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Mrays/s"), std::string::npos) << r.out;
}

TEST(ToolRender, BadArgumentsAndInputs) {
  const std::string hammer = test::quote(test::source_path("examples/data/hammer.obj"));
  EXPECT_EQ(test::run_tool("render " + hammer).exit_code, 2);  // no -o
  EXPECT_EQ(test::run_tool("render " + hammer + " -o x --views 0").exit_code, 2);
  EXPECT_EQ(test::run_tool("render " + hammer + " -o x --layout spiral").exit_code, 2);
  test::ToolRun r = test::run_tool("render " + hammer + " -o x --renderer povray");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("known: embree"), std::string::npos) << r.err;
  const std::string dir = test::scratch_dir("ToolRender.Bad");
  test::write_file(dir + "/file", "keep me");
  r = test::run_tool("render " + hammer + " -o " + test::quote(dir + "/file") + " --views 1 --resolution 16");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not a folder"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_file(dir + "/file"), "keep me");
  r = test::run_tool("render " + test::quote(dir + "/missing.glb") + " -o " + test::quote(dir + "/o"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no such file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace g2p
