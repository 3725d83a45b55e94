// `g2p properties` and `g2p eval mass` as a user runs them.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

TEST(ToolProperties, WritesAReportWithTheHammersCentreOfMassInItsHead) {
  const std::string dir = test::scratch_dir("ToolProperties");
  test::write_file(dir + "/labels.json",
                   R"({"models": {"hammer": {"labels": {"0": "Wood", "1": "Metal"}, "real_mass_kg": [0.5, 2.0]}}})");
  test::ToolRun r =
      test::run_tool("properties " + test::quote(test::source_path("examples/data/hammer.obj")) + " --truth " +
                     test::quote(dir + "/labels.json") + " -o " + test::quote(dir + "/out"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("plausible mass 0.5 - 2 kg"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/out/report.json"));
  EXPECT_EQ(j["parts"].size(), 2u);
  EXPECT_GT(j["object"]["center_of_mass_m"][2].get<double>(), 0.29);
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/completed/completion.json"));
  // A bad estimator setting is a usage error, before any work.
  r = test::run_tool("properties " + test::quote(test::source_path("examples/data/hammer.obj")) + " --truth " +
                     test::quote(dir + "/labels.json") + " -o " + test::quote(dir + "/bad") +
                     " --estimate-set rays=-3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad"));
}

TEST(ToolEvalMass, PrintsTheFourMetrics) {
  const std::string dir = test::scratch_dir("ToolEvalMass");
  test::write_file(dir + "/masses.csv", "object,predicted_kg,true_kg\nchair,2,1\nbottle,1,2\n");
  test::ToolRun r =
      test::run_tool("eval mass " + test::quote(dir + "/masses.csv") + " --json " + test::quote(dir + "/m.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("ADE 1 kg, ALDE 0.6931, APE 0.7500, MnRE 0.5000"), std::string::npos) << r.out;
  EXPECT_NEAR(nlohmann::json::parse(test::read_file(dir + "/m.json"))["mnre"].get<double>(), 0.5, 1e-12);
  test::write_file(dir + "/bad.csv", "object,predicted_kg,true_kg\nchair,two,1\n");
  r = test::run_tool("eval mass " + test::quote(dir + "/bad.csv"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.csv:2"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace g2p
