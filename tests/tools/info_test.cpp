// The g2p tool as a user runs it: exit codes, messages on stderr, JSON output.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using test::quote;
using test::run_tool;
using test::ToolRun;

TEST(ToolInfo, PrintsMeshesFacesMaterialsAndBounds) {
  ToolRun r = run_tool("info " + quote(test::asset_path("SheenChair")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("39936 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'fabric Mystere Mango Velvet'  faces 26176"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bounds (m)"), std::string::npos);
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST(ToolInfo, JsonSummary) {
  ToolRun r = run_tool("info --json --no-textures " + quote(test::source_path("examples/data/hammer.obj")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["faces"], 104);
  EXPECT_EQ(j["materials"].size(), 2u);
  EXPECT_EQ(j["materials"][1]["name"], "steel_head");
  EXPECT_EQ(j["materials"][1]["faces"], 12);
  EXPECT_NEAR(j["bounds_m"]["max"][2].get<double>(), 0.34, 1e-6);
}

// OBJ and MTL files from older tools carry Latin-1 names, and file names can
// be Latin-1 too. Both once threw out of the JSON writers (an abort); names
// are now read as Latin-1 when they are not UTF-8, and paths are written
// with U+FFFD in place of the bytes that are not.
TEST(ToolInfo, Latin1MaterialAndFileNamesAreWrittenAsUtf8) {
  const std::string dir = test::scratch_dir("ToolInfoLatin1");
  const std::string obj =
      "mtllib m.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nusemtl Caf\xe9\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  test::write_file(dir + "/m.mtl", "newmtl Caf\xe9\nKd 0.8 0.2 0.2\n");
  test::write_file(dir + "/caf\xe9.obj", obj);
  ToolRun r = run_tool("info --json " + quote(dir + "/caf\xe9.obj"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["materials"][0]["name"], "Caf\u00e9");
  r = run_tool("run " + quote(dir + "/caf\xe9.obj") + " -o " + quote(dir + "/out") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json run = nlohmann::json::parse(test::read_file(dir + "/out/run.json"));
  EXPECT_NE(run["model"].get<std::string>().find("caf\uFFFD.obj"), std::string::npos) << run["model"];
}

TEST(ToolInfo, EveryMalformedGltfFailsWithAMessage) {
  int checked = 0;
  const std::string root = test::assimp_model("glTF2");
  for (const char* f :
       {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "IndexOutOfRange/IndexOutOfRange.gltf",
        "IndexOutOfRange/AllIndicesOutOfRange.gltf", "IncorrectVertexArrays/Cube.gltf", "MissingBin/BoxTextured.gltf",
        "RecursiveNodes/RecursiveNodes.gltf", "SchemaFailures/sceneWrongType.gltf", "TestNoRootNode/NoScene.gltf",
        "TestNoRootNode/SceneWithoutNodes.gltf", "issue_3269/texcoord_crash.gltf"}) {
    ToolRun r = run_tool("info " + quote(root + "/" + f));
    EXPECT_EQ(r.exit_code, 1) << f;
    EXPECT_NE(r.err.find("g2p info: error: "), std::string::npos) << f << ": " << r.err;
    EXPECT_NE(r.err.find(f), std::string::npos) << "message does not name the file: " << r.err;
    ++checked;
  }
  for (const auto& e : std::filesystem::directory_iterator(root + "/wrongTypes")) {
    if (e.path().extension() != ".gltf") continue;
    ToolRun r = run_tool("info " + quote(e.path().string()));
    EXPECT_EQ(r.exit_code, 1) << e.path();
    EXPECT_FALSE(r.err.empty()) << e.path();
    ++checked;
  }
  EXPECT_EQ(checked, 16);
}

// Files the fuzzers found that crash Debian's assimp: g2p used to end with a
// segmentation fault (exit 139) on the GLB and the PLY; assimp now parses in
// a child process and g2p reports the crash as the file's error.
TEST(ToolInfo, AFileThatCrashesAssimpIsAnErrorNotACrash) {
  for (const char* f :
       {"fuzz/corpus/import_glb/assimp-crash-f307c5ba.glb", "fuzz/corpus/import_obj/assimp-crash-36a93fd0.obj",
        "fuzz/corpus/import_ply/assimp-crash-743ec6ed.ply"}) {
    ToolRun r = run_tool("info " + quote(test::source_path(f)));
    EXPECT_EQ(r.exit_code, 1) << f << ": " << r.err;
    EXPECT_NE(r.err.find("g2p info: error: parse error: "), std::string::npos) << f << ": " << r.err;
  }
  ToolRun glb = run_tool("info " + quote(test::source_path("fuzz/corpus/import_glb/assimp-crash-f307c5ba.glb")));
  EXPECT_NE(glb.err.find("assimp, the model reader, crashed on this file (segmentation fault in libassimp.so"),
            std::string::npos)
      << glb.err;
}

TEST(ToolInfo, UsageErrorsExitWithTwo) {
  EXPECT_EQ(run_tool("").exit_code, 2);
  EXPECT_EQ(run_tool("info").exit_code, 2);
  EXPECT_EQ(run_tool("info --up sideways x.glb").exit_code, 2);
  ToolRun r = run_tool("info --unit parsec " + quote(test::asset_path("Avocado")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("unknown unit 'parsec'"), std::string::npos) << r.err;
  EXPECT_EQ(run_tool("--help").exit_code, 0);
}

TEST(ToolInfo, UpAxisIsCaseInsensitive) {
  ToolRun r = run_tool("info --json --no-textures --up Z " + quote(test::source_path("examples/data/hammer.obj")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Declared Z-up, the Y-up hammer lies on its side: its 34 cm length stays along y.
  EXPECT_NEAR(nlohmann::json::parse(r.out)["bounds_m"]["max"][1].get<double>(), 0.34, 1e-6);
}

}  // namespace
}  // namespace g2p
