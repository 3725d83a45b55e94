// `g2p batch` as a user runs it: bad inputs among good ones with g2p run's
// own messages, exit codes, a manifest's bad row, a real timeout, and Ctrl-C.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

const std::string kQuick = " --views 6 --resolution 160";

std::string hammer_copy(const std::string& dir, const std::string& name) {
  test::write_file(dir + "/" + name + ".obj", test::read_file(test::source_path("examples/data/hammer.obj")));
  test::write_file(dir + "/" + name + ".mtl", test::read_file(test::source_path("examples/data/hammer.mtl")));
  return dir + "/" + name + ".obj";
}

nlohmann::json index_of(const std::string& out) {
  return nlohmann::json::parse(test::read_file(out + "/index.json"))["assets"];
}

nlohmann::json row(const nlohmann::json& index, const std::string& name) {
  for (const auto& r : index)
    if (r["name"] == name) return r;
  return nlohmann::json();
}

TEST(ToolBatch, BadFilesAmongGoodOnesFailWithTheMessagesOfGtoPRun) {
  const std::string dir = test::scratch_dir("ToolBatchMixed");
  const std::string good = hammer_copy(dir, "good");
  test::write_file(dir + "/empty.obj", "");
  test::write_file(dir + "/malformed.obj", "garbage\n");
  test::write_file(dir + "/notes.xyz", "not a model\n");
  const std::vector<std::string> bad{dir + "/empty.obj", dir + "/malformed.obj", dir + "/notes.xyz"};
  std::string inputs = test::quote(good);
  for (const std::string& b : bad) inputs += " " + test::quote(b);
  const std::string out = dir + "/out";
  test::ToolRun r = test::run_tool("batch " + inputs + " -o " + test::quote(out) + kQuick + " --jobs 2");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;  // one succeeded; failures are in the index
  EXPECT_NE(r.out.find("4 assets: 1 ok, 3 failed"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find('\r'), std::string::npos);  // not a terminal: plain lines
  const nlohmann::json index = index_of(out);
  EXPECT_EQ(row(index, "good")["status"], "ok");
  EXPECT_EQ(row(index, "good")["parts"], 2);
  for (const std::string& b : bad) {
    const std::string name = fs::path(b).stem().string();
    // The same message, word for word, as `g2p run` on that file alone.
    test::ToolRun alone = test::run_tool("run " + test::quote(b) + " -o " + test::quote(dir + "/alone") + kQuick);
    ASSERT_EQ(alone.exit_code, 1) << alone.err;
    const std::string message = row(index, name)["error"].get<std::string>();
    EXPECT_FALSE(message.empty()) << name;
    EXPECT_NE(alone.err.find("g2p run: error: " + message), std::string::npos) << alone.err << "\n vs " << message;
    EXPECT_NE(r.err.find("g2p batch: failed: " + name + ": " + message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out + "/" + name));
  }
  EXPECT_NE(row(index, "empty")["error"].get<std::string>().find("the file is empty"), std::string::npos);
  EXPECT_NE(row(index, "notes")["error"].get<std::string>().find("unknown model format"), std::string::npos);

  // --fail-on-error turns a failure into exit 1; the rerun skips everything.
  r = test::run_tool("batch " + inputs + " -o " + test::quote(out) + kQuick + " --fail-on-error");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("0 ok, 0 failed, 4 skipped"), std::string::npos) << r.out;
  // Nothing succeeded: exit 1 even without it.
  r = test::run_tool("batch " + test::quote(bad[0]) + " -o " + test::quote(dir + "/none") + kQuick);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
}

TEST(ToolBatch, AManifestRunsEachRowWithItsFlagsAndABadRowIsNamed) {
  const std::string dir = test::scratch_dir("ToolBatchManifest");
  hammer_copy(dir, "hammer");
  test::write_file(dir + "/assets.csv",
                   "path,name,unit,object\nhammer.obj,in_cm,cm,\nhammer.obj,in_m,,a steel refrigerator\n");
  test::ToolRun r = test::run_tool("batch --manifest " + test::quote(dir + "/assets.csv") + " -o " +
                                   test::quote(dir + "/out") + kQuick + " --unit m -j 2");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json index = index_of(dir + "/out");
  ASSERT_EQ(row(index, "in_cm")["status"], "ok") << row(index, "in_cm");
  ASSERT_EQ(row(index, "in_m")["status"], "ok") << row(index, "in_m");
  EXPECT_EQ(row(index, "in_cm")["origin"], dir + "/assets.csv:2");
  EXPECT_TRUE(fs::exists(dir + "/out/in_cm/in_cm.xml"));  // the row's name is the asset's name
  // The row's --unit cm replaced the batch's --unit m: a hundredth of the size, a millionth of the mass.
  const double ratio = row(index, "in_m")["mass_kg"].get<double>() / row(index, "in_cm")["mass_kg"].get<double>();
  EXPECT_GT(ratio, 1e4) << ratio;
  // The object column: the row's words win over the file's name, and its mass is checked against the kind's.
  EXPECT_EQ(row(index, "in_cm")["kind"], "hammer");  // its names
  EXPECT_EQ(row(index, "in_m")["kind"], "refrigerator");
  EXPECT_EQ(row(index, "in_m")["kind_confidence"], 1.0);
  EXPECT_EQ(row(index, "in_m")["mass_in_kind_range"], "no");  // a 1.4 kg refrigerator
  EXPECT_NE(test::read_file(dir + "/out/index.csv").find(",refrigerator,1,no,"), std::string::npos);
  // The run's warnings reach the index (run.json's, in its JSON and CSV).
  const nlohmann::json warnings = row(index, "in_m")["warnings"];
  ASSERT_TRUE(warnings.is_array()) << row(index, "in_m");
  bool mass_warning = false;
  for (const auto& w : warnings) mass_warning |= w.get<std::string>().rfind("mass: ", 0) == 0;
  EXPECT_TRUE(mass_warning) << warnings;
  EXPECT_NE(test::read_file(dir + "/out/index.csv").find("mass: the object weighs"), std::string::npos);

  test::write_file(dir + "/bad.jsonl",
                   "{\"path\": \"hammer.obj\"}\n{\"path\": \"hammer.obj\", \"height\": \"tall\"}\n");
  r = test::run_tool("batch --manifest " + test::quote(dir + "/bad.jsonl") + " -o " + test::quote(dir + "/bad_out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(dir + "/bad.jsonl:2: height 'tall' is not a positive number"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/bad_out"));
  r = test::run_tool("batch -o " + test::quote(dir + "/x"));
  EXPECT_EQ(r.exit_code, 2);
  r = test::run_tool("batch " + test::quote(dir + "/*.fbx") + " -o " + test::quote(dir + "/x"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("no file matches"), std::string::npos) << r.err;
}

TEST(ToolBatch, ARunPastTheTimeoutIsStoppedAndLeavesNothingBehind) {
  const std::string dir = test::scratch_dir("ToolBatchTimeout");
  // The chair takes several seconds at the default views: past a 1 s limit.
  test::ToolRun r = test::run_tool("batch " + test::quote(test::asset_path("SheenChair")) + " -o " +
                                   test::quote(dir + "/out") + " --timeout 1");
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;  // nothing succeeded
  const nlohmann::json index = index_of(dir + "/out");
  ASSERT_EQ(index.size(), 1u);
  EXPECT_EQ(index[0]["status"], "failed");
  EXPECT_EQ(index[0]["error"], "timed out after 1 s");
  EXPECT_LT(index[0]["seconds"].get<double>(), 8.0);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir + "/out")) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{".g2p-batch.lock", "index.csv", "index.json"}));
}

// Ctrl-C (and SIGTERM) mid-batch: finished assets stay, the index is valid,
// nothing half-written remains, and a rerun finishes the rest.
class ToolBatchSignal : public ::testing::TestWithParam<int> {};

TEST_P(ToolBatchSignal, StopsCleanlyAndARerunGoesOn) {
  const int signal = GetParam();
  const std::string dir = test::scratch_dir("ToolBatchSignal" + std::to_string(signal));
  std::vector<std::string> args{"batch"};
  fs::create_directories(dir + "/models");
  for (int i = 0; i < 6; ++i) args.push_back(hammer_copy(dir + "/models", "h" + std::to_string(i)));
  const std::string out = dir + "/out", err = dir + "/err.txt";
  for (const char* a : {"-o", out.c_str(), "--views", "6", "--resolution", "160"}) args.emplace_back(a);
  const pid_t pid = test::spawn_tool(args, err);
  ASSERT_GT(pid, 0);
  // Stop once the first asset is done (its progress line), while the second runs.
  const auto start = std::chrono::steady_clock::now();
  while (test::read_file(err).find(": ok") == std::string::npos &&
         std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the next asset is under way
  ASSERT_EQ(::kill(pid, signal), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << test::read_file(err);
  EXPECT_EQ(WEXITSTATUS(status), 128 + signal) << test::read_file(err);
  EXPECT_NE(test::read_file(err).find("finished assets and the index are kept"), std::string::npos)
      << test::read_file(err);

  const nlohmann::json index = index_of(out);
  std::size_t ok = 0, cancelled = 0;
  for (const auto& r : index) {
    if (r["status"] == "ok") {
      ++ok;
      EXPECT_TRUE(fs::exists(out + "/" + r["name"].get<std::string>() + "/run.json")) << r;
    } else {
      EXPECT_EQ(r["status"], "cancelled") << r;
      ++cancelled;
    }
  }
  EXPECT_GE(ok, 1u);
  EXPECT_LT(ok, 6u) << "the batch ended before the signal";
  std::size_t folders = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(name[0] != '.' || name == ".g2p-batch.lock") << "left behind: " << name;
    if (e.is_directory()) ++folders;
  }
  EXPECT_EQ(folders, ok);  // a folder for each finished asset, none half-written

  test::ToolRun rerun = test::run_tool("batch " + test::quote(dir + "/models") + " -o " + test::quote(out) + kQuick);
  ASSERT_EQ(rerun.exit_code, 0) << rerun.out << rerun.err;
  EXPECT_NE(rerun.out.find(std::to_string(6 - ok) + " ok, 0 failed, " + std::to_string(ok) + " skipped"),
            std::string::npos)
      << rerun.out;
}

INSTANTIATE_TEST_SUITE_P(IntAndTerm, ToolBatchSignal, ::testing::Values(SIGINT, SIGTERM));

TEST(ToolBatch, HelpListsTheOptionsAndTheExitCodes) {
  test::ToolRun r = test::run_tool("batch --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag : {"--manifest", "--jobs", "--timeout", "--memory-limit", "--retry-failed", "--fail-on-error",
                           "--views", "--segmenter", "--unit"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
  EXPECT_NE(r.out.find("130 stopped"), std::string::npos);
}

}  // namespace
}  // namespace g2p
