// `g2p run` as a user runs it: the whole pipeline, its exit codes, its JSON
// summary, degraded optional stages, and a folder the other commands accept.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "g2p/io.h"
#include "g2p/options_file.h"
#include "segment/segment_fixtures.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

const std::string kQuick = " --views 6 --resolution 160";
// ...and a coarse closed volume and one hull per part, for the tests about
// labels: completion and decomposition are most of a run under ASan.
const std::string kLabelsOnly = kQuick + " --complete-set resolution=48 --decomposer hull";

std::string hammer() { return test::quote(test::source_path("examples/data/hammer.obj")); }

// A run's folder holds its options (options.json); `g2p run --options` with
// that file gives the same result, and flags beside it are refused.
TEST(ToolRun, AnOptionsFileRepeatsARun) {
  const std::string dir = test::scratch_dir("ToolRunOptions");
  test::ToolRun first = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/first") + kLabelsOnly +
                                       " --height 0.5 --format urdf,mjcf --json");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string file = dir + "/first/options.json";
  Result<RunOptions> written = read_options_file(file);
  ASSERT_TRUE(written.ok()) << written.status().to_string();
  EXPECT_DOUBLE_EQ(written->pipeline.import.height_m, 0.5);
  EXPECT_EQ(written->pipeline.views.num_views, 6);
  EXPECT_EQ(written->pipeline.decomposer.name, "hull");
  EXPECT_EQ(written->pipeline.completer.settings, (BackendSettings{{"resolution", "48"}}));

  test::ToolRun again = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/again") + " --options " +
                                       test::quote(file) + " --json");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const nlohmann::json a = nlohmann::json::parse(first.out), b = nlohmann::json::parse(again.out);
  EXPECT_EQ(b["object"]["mass_kg"], a["object"]["mass_kg"]);
  EXPECT_EQ(b["parts"].size(), a["parts"].size());
  EXPECT_TRUE(fs::exists(dir + "/again/hammer.urdf"));
  EXPECT_FALSE(fs::exists(dir + "/again/hammer.sdf"));
  EXPECT_EQ(test::read_file(dir + "/again/options.json"), test::read_file(file));

  // A flag beside --options, a bad key or value: exit 2 naming it, nothing written.
  test::ToolRun both = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/both") + " --options " +
                                      test::quote(file) + " --views 4");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("--views and --options exclude each other"), std::string::npos) << both.err;
  test::write_file(dir + "/bad.json", R"({"views": {"count": "six"}})");
  test::ToolRun bad = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/bad") + " --options " +
                                     test::quote(dir + "/bad.json"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("bad.json: views.count: expected an integer"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir + "/both"));
  EXPECT_FALSE(fs::exists(dir + "/bad"));
}

TEST(ToolRun, HammerToAssetsWithAJsonSummary) {
  const std::string dir = test::scratch_dir("ToolRun");
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + kQuick + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);  // stdout is the JSON alone
  EXPECT_EQ(j["format"], "g2p-run");
  EXPECT_EQ(j["parts"].size(), 2u);
  EXPECT_GT(j["object"]["center_of_mass_m"][2].get<double>(), 0.25);
  EXPECT_EQ(j["assets"].size(), 4u);
  for (const auto& f : j["assets"]) EXPECT_TRUE(fs::exists(dir + "/out/" + f.get<std::string>())) << f;
  EXPECT_TRUE(fs::exists(dir + "/out/summary.html"));
  EXPECT_EQ(r.err.find("\r"), std::string::npos);  // not a terminal: plain progress lines
  EXPECT_NE(r.err.find("g2p run: complete done"), std::string::npos) << r.err;

  // The folder is a source for the single-stage commands: export closes its
  // parts again (a run keeps completed/ only with --save-intermediates) and
  // weighs them the same.
  EXPECT_FALSE(fs::exists(dir + "/out/completed"));
  r = test::run_tool("export " + test::quote(dir + "/out") + " -o " + test::quote(dir + "/again") + " --format mjcf");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("complete "), std::string::npos) << r.out;  // closed again
  EXPECT_EQ(nlohmann::json::parse(test::read_file(dir + "/again/report.json"))["object"]["mass_kg"],
            j["object"]["mass_kg"]);

  // ...and refine reruns stage 4 on it.
  r = test::run_tool("refine " + test::quote(dir + "/out") + " -o " + test::quote(dir + "/refined") +
                     " --refiner none");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("2 parts"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir + "/refined/faces.csv"));
  EXPECT_EQ(nlohmann::json::parse(test::read_file(dir + "/out/manifest.json"))["project"]["vote"], "hard");

  // An existing output is a usage error and stays untouched; --overwrite replaces it.
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + kQuick);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + kQuick +
                     " --overwrite --format urdf --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out/hammer.urdf"));
  EXPECT_FALSE(fs::exists(dir + "/out/hammer.xml"));

  // --overwrite never replaces a folder that holds the model, the working
  // directory or files that are not a g2p output; each is refused before any
  // work, exit 2, and nothing is touched.
  fs::copy_file(test::source_path("examples/data/hammer.obj"), dir + "/out/hammer_in.obj");
  r = test::run_tool("run " + test::quote(dir + "/out/hammer_in.obj") + " -o " + test::quote(dir + "/out") + kQuick +
                     " --overwrite");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("holds the model being run"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out/hammer_in.obj"));
  // From inside the folder, as ../out: the same folder, the working directory.
  r = test::run_command("cd " + test::quote(dir + "/out") + " && " + test::quote(G2P_TEST_TOOL) + " run " + hammer() +
                        " -o ../out" + kQuick + " --overwrite");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is or holds the working directory"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out/hammer.urdf"));
  fs::create_directories(dir + "/mine");
  test::write_file(dir + "/mine/notes.txt", "precious");
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/mine") + kQuick + " --overwrite");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is not a g2p output folder"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_file(dir + "/mine/notes.txt"), "precious");
  fs::create_directories(dir + "/empty");
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/empty") + kQuick + " --overwrite -q");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/empty/run.json"));

  // --soft reaches the project stage: soft votes, the same two parts on the hammer.
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/soft") + kQuick + " --soft --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["parts"].size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(test::read_file(dir + "/soft/manifest.json"))["project"]["vote"], "soft");
}

TEST(ToolRun, TheGlbOfATexturedAssetPassesTheKhronosValidator) {
  // A real glTF with base-colour, metallic-roughness and normal textures: the
  // exported GLB carries its materials and textures, and the hulls.
  const std::string dir = test::scratch_dir("ToolRunKhronos");
  test::ToolRun r = test::run_tool("run " + test::quote(test::asset_path("WaterBottle")) + " -o " +
                                   test::quote(dir + "/out") + kQuick + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  std::string glb;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const auto& f : j["assets"])
    if (fs::path(f.get<std::string>()).extension() == ".glb") glb = dir + "/out/" + f.get<std::string>();
  ASSERT_FALSE(glb.empty()) << r.out;
  const test::ValidatorRun v = test::run_gltf_validator(glb);
  if (!v.available) GTEST_SKIP() << "node or the npm gltf-validator is missing: run scripts/install-deps.sh";
  EXPECT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  EXPECT_NE(v.run.out.find(": 0 errors"), std::string::npos) << v.run.out;
}

// The hammer as an image-to-3D generator would write it: scaled so that its
// longest side is 1 m. Returns the path; `real_longest` gets the true side.
std::string normalised_hammer(const std::string& dir, double& real_longest) {
  std::istringstream in(test::read_file(test::source_path("examples/data/hammer.obj")));
  std::vector<std::string> lines;
  Eigen::AlignedBox3d box;
  for (std::string line; std::getline(in, line);) {
    lines.push_back(line);
    if (line.rfind("v ", 0) != 0) continue;
    Eigen::Vector3d p;
    std::istringstream(line.substr(2)) >> p.x() >> p.y() >> p.z();
    box.extend(p);
  }
  real_longest = box.sizes().maxCoeff();
  std::ostringstream out;
  for (const std::string& line : lines) {
    if (line.rfind("v ", 0) != 0) {
      out << line << "\n";
      continue;
    }
    Eigen::Vector3d p;
    std::istringstream(line.substr(2)) >> p.x() >> p.y() >> p.z();
    p /= real_longest;
    out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  test::write_file(dir + "/hammer.obj", out.str());
  test::write_file(dir + "/hammer.mtl", test::read_file(test::source_path("examples/data/hammer.mtl")));
  return dir + "/hammer.obj";
}

TEST(ToolRun, ANormalisedMeshWarnsAndItsRealSizeScalesTheMass) {
  const std::string dir = test::scratch_dir("ToolRunSize");
  double real = 0;
  const std::string model = normalised_hammer(dir, real);
  // --size-from file: the file's size, as a run that cannot tell what the object is.
  test::ToolRun as_is =
      test::run_tool("run " + test::quote(model) + " -o " + test::quote(dir + "/as_is") + kQuick + " --size-from file");
  ASSERT_EQ(as_is.exit_code, 0) << as_is.err;
  EXPECT_NE(as_is.err.find("its size is kept as the file's (--size-from file)"), std::string::npos) << as_is.err;
  EXPECT_NE(as_is.err.find("looks normalised"), std::string::npos) << as_is.err;
  EXPECT_NE(as_is.err.find("--height or --longest-side"), std::string::npos) << as_is.err;
  const nlohmann::json run = nlohmann::json::parse(test::read_file(dir + "/as_is/run.json"));
  EXPECT_NE(run["warnings"].dump().find("looks normalised"), std::string::npos) << run["warnings"];
  EXPECT_NE(test::read_file(dir + "/as_is/summary.html").find("looks normalised"), std::string::npos);

  char side[32];
  std::snprintf(side, sizeof side, "%.6f", real);
  test::ToolRun sized = test::run_tool("run " + test::quote(model) + " -o " + test::quote(dir + "/sized") + kQuick +
                                       " --longest-side " + side);
  ASSERT_EQ(sized.exit_code, 0) << sized.err;
  EXPECT_EQ(sized.err.find("looks normalised"), std::string::npos) << sized.err;
  const nlohmann::json a = nlohmann::json::parse(test::read_file(dir + "/as_is/report.json"))["object"];
  const nlohmann::json b = nlohmann::json::parse(test::read_file(dir + "/sized/report.json"))["object"];
  EXPECT_TRUE(a["size"]["looks_normalised"].get<bool>());
  EXPECT_EQ(a["size"]["scale_source"], "file");
  EXPECT_NEAR(a["size"]["longest_side_m"].get<double>(), 1.0, 1e-4);
  EXPECT_FALSE(b["size"]["looks_normalised"].get<bool>());
  EXPECT_EQ(b["size"]["scale_source"], "longest-side");
  EXPECT_NEAR(b["size"]["longest_side_m"].get<double>(), real, 1e-4);
  // At its real size it is the bundled hammer again, with the same mass; at
  // 1 m it weighs several times more (not quite the cube: the wall rules
  // make a large head hollow).
  test::ToolRun original = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/original") + kQuick);
  ASSERT_EQ(original.exit_code, 0) << original.err;
  const double real_mass =
      nlohmann::json::parse(test::read_file(dir + "/original/report.json"))["object"]["mass_kg"].get<double>();
  EXPECT_NEAR(b["mass_kg"].get<double>() / real_mass, 1.0, 0.01) << b["mass_kg"] << " vs " << real_mass;
  EXPECT_GT(a["mass_kg"].get<double>(), 2.5 * real_mass);

  // By default its name says hammer, and a hammer's typical size is assumed, and said.
  test::ToolRun by_kind = test::run_tool("run " + test::quote(model) + " -o " + test::quote(dir + "/kind") + kQuick);
  ASSERT_EQ(by_kind.exit_code, 0) << by_kind.err;
  EXPECT_NE(by_kind.err.find("scaled to a hammer's typical longest side"), std::string::npos) << by_kind.err;
  EXPECT_NE(by_kind.out.find("object: hammer"), std::string::npos) << by_kind.out;
  const nlohmann::json k = nlohmann::json::parse(test::read_file(dir + "/kind/report.json"));
  EXPECT_EQ(k["object"]["size"]["scale_source"], "kind");
  EXPECT_EQ(k["identification"]["kind"], "hammer");
  EXPECT_NEAR(k["object"]["size"]["longest_side_m"].get<double>(), k["identification"]["size_assumed_m"].get<double>(),
              1e-4);
  EXPECT_LT(k["object"]["mass_kg"].get<double>(), a["mass_kg"].get<double>());

  test::ToolRun both = test::run_tool("run " + test::quote(model) + " -o " + test::quote(dir + "/both") +
                                      " --height 0.3 --longest-side 0.4");
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.err.find("--height and --longest-side"), std::string::npos) << both.err;
  EXPECT_FALSE(fs::exists(dir + "/both"));
}

TEST(ToolRun, BadFlagsAreUsageErrorsAndWriteNothing) {
  const std::string dir = test::scratch_dir("ToolRunBad");
  struct Case {
    std::string flags, message;
  };
  for (const Case& c :
       {Case{"--segmenter nope", "no segmenter named 'nope'"}, Case{"--complete-set resolution", "--complete-set"},
        Case{"--vlm-url http://127.0.0.1:9/v1", "--vlm-url"}, Case{"--format obj", "obj"}}) {
    test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + " " + c.flags);
    EXPECT_EQ(r.exit_code, 2) << c.flags << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.flags << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir + "/out")) << c.flags;
  }
  test::ToolRun r = test::run_tool("run " + test::quote(dir + "/missing.glb") + " -o " + test::quote(dir + "/out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.glb"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

TEST(ToolRun, ABadOutputFolderFailsBeforeAnyWork) {
  const std::string dir = test::scratch_dir("ToolRunBadOutput");
  test::write_file(dir + "/a_file", "not a folder");
  const std::string decompose_set = " --decompose-set resolution=16";  // a cheap run if the check were late
  for (const std::string& out : {dir + "/a_file", dir + "/a_file/sub"}) {
    test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(out) + decompose_set);
    EXPECT_EQ(r.exit_code, 2) << out << "\n" << r.err;
    EXPECT_NE(r.err.find("-o "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not a folder"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("render"), std::string::npos) << "the pipeline ran first: " << r.err;
  }
  EXPECT_EQ(test::read_file(dir + "/a_file"), "not a folder");  // untouched
}

TEST(ToolRun, TooLittleMemoryIsACleanErrorNotACrash) {
  const std::string dir = test::scratch_dir("ToolRunMemory");
  // Refused before any work: 11 views of 512 x 512 need about half a GiB.
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + " --memory-limit 0.1");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("out of memory"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--resolution"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("render done"), std::string::npos) << "the run started: " << r.err;
  // An allocation that fails anyway (a 1.2 GB address space for 2048-pixel
  // views) ends the run with the same message and exit code, not an abort.
  const std::string err = dir + "/err.txt";
  const std::string command = "ulimit -v 1200000; exec " + test::quote(G2P_TEST_TOOL) + " run " + hammer() + " -o " +
                              test::quote(dir + "/out") + " --resolution 2048 --memory-limit 100 -q 2>" +
                              test::quote(err);
  const int status = std::system(("sh -c " + test::quote(command)).c_str());
  ASSERT_TRUE(WIFEXITED(status)) << test::read_file(err);
  EXPECT_EQ(WEXITSTATUS(status), 1) << test::read_file(err);
  EXPECT_NE(test::read_file(err).find("out of memory"), std::string::npos) << test::read_file(err);
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

TEST(ToolRun, AnUnreachableVlmDegradesToTheProjectedLabelsAndTheTable) {
  const std::string dir = test::scratch_dir("ToolRunVlm");
  const std::string secret = "sk-test-secret-4711";
  ::setenv("G2P_TEST_VLM_KEY", secret.c_str(), 1);
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + kQuick +
                                   " --refiner vlm --vlm-url 'http://me:pw-4711@127.0.0.1:9/v1?key=qk-4711'"
                                   " --vlm-model test"
                                   " --refine-set retries=0 --refine-set timeout=5"
                                   " --refine-set api_key_env=G2P_TEST_VLM_KEY --estimator vlm"
                                   " --estimate-set retries=0 --estimate-set api_key_env=G2P_TEST_VLM_KEY");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("warning: refine (vlm) failed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("warning: properties (vlm): 2 of 2 parts fell back"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/out/run.json"));
  EXPECT_EQ(j["warnings"].size(), 2u);
  // The table's values stand: the steel head still makes the centre of mass high.
  EXPECT_GT(j["object"]["center_of_mass_m"][2].get<double>(), 0.25);
  EXPECT_EQ(j["parts"].size(), 2u);
  const nlohmann::json refine = nlohmann::json::parse(test::read_file(dir + "/out/refine.json"));
  EXPECT_TRUE(refine.contains("error"));
  // The key's value, and a password or key in the URL, never reach the
  // output or any file; the URL is shown redacted.
  EXPECT_NE(r.err.find("http://***@127.0.0.1:9/v1/chat/completions?key=***"), std::string::npos) << r.err;
  for (const std::string& s : {secret, std::string("pw-4711"), std::string("qk-4711")}) {
    EXPECT_EQ(r.out.find(s), std::string::npos) << s;
    EXPECT_EQ(r.err.find(s), std::string::npos) << s;
    for (const auto& e : fs::recursive_directory_iterator(dir + "/out"))
      if (e.is_regular_file()) EXPECT_EQ(test::read_file(e.path().string()).find(s), std::string::npos) << e.path();
  }
}

// Ctrl-C during a run: exit code 130, nothing written, no temporary folder left.
class ToolRunSignal : public ::testing::TestWithParam<int> {};

TEST_P(ToolRunSignal, CancelsAndWritesNothing) {
  const int signal = GetParam();
  const std::string dir = test::scratch_dir("ToolRunSignal" + std::to_string(signal));
  const std::string out = dir + "/out", err = dir + "/err.txt";
  const std::string model = test::asset_path("SheenChair");  // several seconds: time to interrupt it
  const pid_t pid = test::spawn_tool({"run", model, "-o", out}, err);
  ASSERT_GT(pid, 0);
  // Interrupt once rendering has begun (progress lines on stderr).
  const auto start = std::chrono::steady_clock::now();
  while (test::read_file(err).find("render") == std::string::npos &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(::kill(pid, signal), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << test::read_file(err);
  EXPECT_EQ(WEXITSTATUS(status), 128 + signal) << test::read_file(err);
  EXPECT_NE(test::read_file(err).find("nothing was written"), std::string::npos) << test::read_file(err);
  std::vector<std::string> left;  // no output and no hidden temporary folder
  for (const auto& e : fs::directory_iterator(dir)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"err.txt"});
}

// Ctrl-C, and TERM as `timeout`, CI runners and containers send it.
INSTANTIATE_TEST_SUITE_P(IntAndTerm, ToolRunSignal, ::testing::Values(SIGINT, SIGTERM));

// A closed 2 mm oak board is kept as given (exact mass), and the same board
// without its four edge faces (open: two sheets) is closed on the grid and
// checked against the volume its faces enclose: the warning reaches run.json,
// report.json and summary.html (#50).
TEST(ToolRun, AClosedBoardKeepsItsMassAndAnOpenOneIsCheckedAgainstItsFaces) {
  const std::string dir = test::scratch_dir("ToolRunBoards");
  const std::string corners =
      "v -0.3 -0.15 -0.001\nv -0.3 -0.15 0.001\nv -0.3 0.15 -0.001\nv -0.3 0.15 0.001\n"
      "v 0.3 -0.15 -0.001\nv 0.3 -0.15 0.001\nv 0.3 0.15 -0.001\nv 0.3 0.15 0.001\n";
  const std::string faces_top_bottom = "f 1 3 7\nf 1 7 5\nf 2 6 8\nf 2 8 4\n";
  const std::string faces_edges = "f 1 2 4\nf 1 4 3\nf 5 7 8\nf 5 8 6\nf 1 5 6\nf 1 6 2\nf 3 4 8\nf 3 8 7\n";
  test::write_file(dir + "/oak.mtl", "newmtl oak\nKd 0.6 0.4 0.2\n");
  test::write_file(dir + "/closed_board.obj",
                   "mtllib oak.mtl\nusemtl oak\n" + corners + faces_top_bottom + faces_edges);
  test::write_file(dir + "/open_board.obj", "mtllib oak.mtl\nusemtl oak\n" + corners + faces_top_bottom);

  test::ToolRun r = test::run_tool("run " + test::quote(dir + "/closed_board.obj") + " --unit m -o " +
                                   test::quote(dir + "/closed") + " --views 6 --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  nlohmann::json report = nlohmann::json::parse(test::read_file(dir + "/closed/report.json"));
  const double oak = report["parts"][0]["density_kg_m3"].get<double>();
  EXPECT_NEAR(report["object"]["mass_kg"].get<double>(), oak * 0.6 * 0.3 * 0.002, 1e-6);
  EXPECT_TRUE(report["parts"][0]["completion_ok"].get<bool>());
  nlohmann::json run = nlohmann::json::parse(test::read_file(dir + "/closed/run.json"));
  for (const auto& w : run["warnings"]) EXPECT_EQ(w.get<std::string>().find("volume"), std::string::npos) << w;

  r = test::run_tool("run " + test::quote(dir + "/open_board.obj") + " --unit m -o " + test::quote(dir + "/open") +
                     " --views 6");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  report = nlohmann::json::parse(test::read_file(dir + "/open/report.json"));
  run = nlohmann::json::parse(test::read_file(dir + "/open/run.json"));
  const double mass = report["object"]["mass_kg"].get<double>();
  const double off = mass / (oak * 0.6 * 0.3 * 0.002) - 1.0;
  // Whatever the grid makes of it, a mass more than 10 % off is never silent.
  bool warned = false;
  for (const auto& w : run["warnings"]) warned |= w.get<std::string>().rfind("complete: ", 0) == 0;
  EXPECT_EQ(warned, std::abs(off) > 0.1) << off << " " << run["warnings"];
  if (warned) {
    bool any_failed = false;
    for (const auto& p : report["parts"]) any_failed |= !p["completion_ok"].get<bool>();
    EXPECT_TRUE(any_failed);
    EXPECT_NE(test::read_file(dir + "/open/summary.html").find("the input's faces enclose"), std::string::npos);
    EXPECT_NE(r.err.find("warning: complete: "), std::string::npos) << r.err;
  }
}

// Issue #31's first item: with no segmenter option, a real image-to-3D mesh
// (TRELLIS: one material, a baked atlas, no names, metallic 1) gets more
// than one class; the old default read it as one class, Metal.
TEST(ToolRun, TheDefaultDecomposesARealGeneratorMesh) {
  const std::string dir = test::scratch_dir("ToolRunGeneratorMesh");
  const std::string chair = test::generated_path("trellis_shell_chair.glb");
  G2P_SKIP_WITHOUT(chair);
  const std::string glb = test::quote(chair);
  std::set<std::string> classes[2];
  for (int old = 0; old < 2; ++old) {
    test::ToolRun r =
        test::run_tool("run " + glb + " --height 0.82 -o " + test::quote(dir + "/out" + std::to_string(old)) +
                       kLabelsOnly + (old ? " --segmenter pbr" : "") + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    for (const auto& part : j["parts"]) classes[old].insert(part["material"].get<std::string>());
    // No stage degraded: a mass check against the kind may speak, and the
    // volume check of kLabelsOnly's coarse grid (nothing else of complete's).
    for (const auto& w : j["warnings"]) {
      const std::string text = w.get<std::string>();
      const bool volume_check = text.rfind("complete: ", 0) == 0 && text.find(" % allowed)") != std::string::npos;
      EXPECT_TRUE(text.rfind("mass:", 0) == 0 || volume_check) << j["warnings"].dump();
    }
  }
  EXPECT_GE(classes[0].size(), 2u) << "the default";
  EXPECT_EQ(classes[1], std::set<std::string>{"Metal"}) << "pbr";
}

// The region classifier on a real generator mesh: one decision per region,
// the stage not degraded; without its card it says so and smooths instead.
TEST(ToolRun, TheRegionsRefinerDecidesPerRegionOnAGeneratorMesh) {
  const std::string dir = test::scratch_dir("ToolRunRegions");
  const std::string chair = test::generated_path("trellis_shell_chair.glb");
  G2P_SKIP_WITHOUT(chair);
  const std::string glb = test::quote(chair);
  test::ToolRun r = test::run_tool("run " + glb + " --height 0.82 -o " + test::quote(dir + "/out") + kLabelsOnly +
                                   " --refiner regions --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  for (const auto& w : j["warnings"])  // the stages ran undegraded (a mass check against the kind may speak)
    EXPECT_EQ(w.get<std::string>().rfind("mass:", 0), 0u) << j["warnings"].dump();
  std::set<std::string> classes;
  for (const auto& part : j["parts"]) classes.insert(part["material"].get<std::string>());
  EXPECT_GE(classes.size(), 2u) << j["parts"].dump();
  const nlohmann::json refine = nlohmann::json::parse(test::read_file(dir + "/out/refine.json"));
  EXPECT_EQ(refine["refiner"], "regions");
  // Its note: "regions: R regions, D decided by the classifier (...)": D > 0.
  int decided = 0;
  for (const auto& note : refine["notes"]) {
    const std::string text = note.get<std::string>();
    const std::size_t at = text.find(" decided by the classifier");
    if (text.rfind("regions: ", 0) != 0 || at == std::string::npos) continue;
    decided = std::stoi(text.substr(text.rfind(' ', at - 1) + 1));
  }
  EXPECT_GT(decided, 0) << refine.dump();

  // A card that cannot be read: the run goes on with smooth and says why.
  test::write_file(dir + "/broken-card.json", "{\"format\": \"something else\"}");
  r = test::run_tool("run " + glb + " --height 0.82 -o " + test::quote(dir + "/broken") + kLabelsOnly +
                     " --refiner regions --refine-set card=" + test::quote(dir + "/broken-card.json") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  j = nlohmann::json::parse(r.out);
  const std::string warnings = j["warnings"].dump();
  EXPECT_NE(warnings.find("broken-card.json"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("smooth refiner ran instead"), std::string::npos) << warnings;
  // A card that is not there is a mistake in the command: refused, nothing written.
  r = test::run_tool("run " + glb + " -o " + test::quote(dir + "/missing") + kQuick +
                     " --refiner regions --refine-set card=" + test::quote(dir + "/no-such-card.json"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no-such-card.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/missing"));
}

// A real multi-material chair merged into one material with a colour atlas
// and no names: with `--segmenter hybrid`, `g2p run` finds more than one
// material (issue #31).
TEST(ToolRun, HybridDecomposesAGeneratedLookingMesh) {
  const std::string dir = test::scratch_dir("ToolRunGenerated");
  Result<Model> chair = load_model(test::asset_path("SheenChair"));
  ASSERT_TRUE(chair.ok()) << chair.status().to_string();
  const std::string obj = test::write_atlas_obj(test::one_atlas_material(*chair), dir, "chair");
  // The fixture's atlas is one tile per source material, a few UV charts,
  // not a baked atlas's hundreds: atlas_charts=0 counts any texture.
  test::ToolRun r = test::run_tool("run " + test::quote(obj) + " --up z --segmenter hybrid --set atlas_charts=0 -o " +
                                   test::quote(dir + "/out") + kLabelsOnly + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::set<std::string> materials;
  for (const auto& part : j["parts"]) materials.insert(part["material"].get<std::string>());
  EXPECT_GE(materials.size(), 2u) << j["parts"].dump();
  // Nothing degraded. The one warning allowed is the chair's mass check: the
  // file's name makes it a chair, whose usual 2.5-12 kg this merged fixture,
  // weighed at quick settings, may leave (13 kg at the run's defaults).
  for (const auto& w : j["warnings"])
    EXPECT_EQ(w.get<std::string>().rfind("mass: the object weighs", 0), 0u) << j["warnings"].dump();
}

// `--base-color-only` runs a curated asset as a generator would emit it: the
// candle holder's glass is glass by its authored transmission; without it,
// metallic at glTF's default of 1 reads as metal everywhere (`pbr`).
TEST(ToolRun, BaseColorOnlyDropsTheAuthoredPbrAsAGeneratorWould) {
  const std::string dir = test::scratch_dir("ToolRunBaseColorOnly");
  const std::string glb = test::quote(test::asset_path("GlassHurricaneCandleHolder"));
  std::set<std::string> classes[2];
  for (int reduced = 0; reduced < 2; ++reduced) {
    const std::string out = dir + "/out" + std::to_string(reduced);
    test::ToolRun r = test::run_tool("run " + glb + " -o " + test::quote(out) + kLabelsOnly +
                                     " --anonymize-names --segmenter pbr --format mjcf --json" +
                                     (reduced ? " --base-color-only" : ""));
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    for (const auto& part : j["parts"]) classes[reduced].insert(part["material"].get<std::string>());
    const nlohmann::json project = nlohmann::json::parse(test::read_file(out + "/manifest.json"));
    EXPECT_EQ(project["base_color_only"], reduced == 1);
  }
  EXPECT_EQ(classes[0].count("Glass"), 1u) << "PBR kept";
  EXPECT_EQ(classes[1], std::set<std::string>{"Metal"}) << "base colour only";
}

TEST(ToolRun, HelpListsEveryStageFlagAndTheExitCodes) {
  test::ToolRun r = test::run_tool("run --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag :
       {"--segmenter", "--refiner", "--completer", "--estimator", "--views", "--resolution", "--materials", "--soft",
        "--vlm-url", "--vlm-model", "--format", "--json", "--save-intermediates"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
  EXPECT_NE(r.out.find("130 cancelled"), std::string::npos);
  // The backends and defaults come from the library: its registries and options.
  EXPECT_NE(r.out.find("Segmenter: pbr, onnx"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1000]=11"), std::string::npos) << r.out;  // --views: ViewOptions::num_views
  EXPECT_NE(r.out.find("`g2p run --settings refine:NAME` lists them"), std::string::npos);
}

// `--settings` lists a backend's settings from its own description, exits 0
// without a model, and the reference page holds this build's listing.
TEST(ToolRun, SettingsListsEachBackendAsTheReferencePageDoes) {
  test::ToolRun r = test::run_tool("run --settings voxel-cut");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("decompose voxel-cut (--decompose-set KEY=VALUE):"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("resolution                 an integer in 8..256 (cells) (default 64)"), std::string::npos)
      << r.out;

  r = test::run_tool("run --settings paint:vlm");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no stage named 'paint'"), std::string::npos) << r.err;

  // A bad setting is a usage error before any work, naming the setting.
  const std::string dir = test::scratch_dir("ToolRunSettings");
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/out") + " --set share=2");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("share takes a number in (0, 1]"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));

  r = test::run_tool("run --settings all");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream file(test::source_path("docs/settings.md"));
  std::stringstream page;
  page << file.rdbuf();
  // Each backend's block (its heading line up to the next) appears verbatim:
  // scripts/settings_doc.sh rewrites the page when they differ.
  std::size_t blocks = 0;
  for (std::size_t at = 0; at < r.out.size();) {
    std::size_t next = at;
    do {
      next = r.out.find('\n', next);
      next = next == std::string::npos ? r.out.size() : next + 1;
    } while (next < r.out.size() && r.out[next] == ' ');
    const std::string block = r.out.substr(at, next - at);
    EXPECT_NE(page.str().find(block), std::string::npos) << "docs/settings.md lacks (run scripts/settings_doc.sh):\n"
                                                         << block;
    ++blocks;
    at = next;
  }
  EXPECT_GE(blocks, 20u);
}

}  // namespace
}  // namespace g2p
