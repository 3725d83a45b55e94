// --overrides as a user gives it: `g2p run` applies a correction file, the
// run's folder keeps it, the stage commands rerun only what follows the
// change, and a bad file changes and writes nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

std::string hammer() { return test::quote(test::source_path("examples/data/hammer.obj")); }

nlohmann::json json_of(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

// The hammer's handle (part 0 of a default run, 92 faces of wood) becomes
// plastic; its steel head becomes a hollow casting of 7000 kg/m^3.
const char* kFix = R"({"format": "g2p-overrides", "version": 1, "model": "hammer.obj", "faces_total": 104,
  "overrides": [{"part": 0, "was": {"class": "Wood", "faces": 92}, "class": "Plastic"},
                {"part": 1, "was": {"class": "Metal"}, "structure": "hollow", "wall_thickness_m": 0.004,
                 "density_kg_m3": 7000}]})";

TEST(ToolOverrides, RunAppliesTheCorrectionsAndTheStageCommandsAgree) {
  const std::string dir = test::scratch_dir("ToolOverrides");
  test::write_file(dir + "/fix.json", kFix);
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/plain") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json plain = json_of(dir + "/plain/run.json");
  ASSERT_EQ(plain["parts"].size(), 2u);
  ASSERT_EQ(plain["parts"][0]["material"], "Wood");

  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/fixed") + " -q --overrides " +
                     test::quote(dir + "/fix.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("correction: entry 1: part 0 (Wood) is now Plastic (92 faces changed class)"), std::string::npos)
      << r.err;
  const nlohmann::json fixed = json_of(dir + "/fixed/run.json");
  ASSERT_EQ(fixed["parts"].size(), 2u);
  EXPECT_EQ(fixed["parts"][0]["material"], "Plastic");
  EXPECT_EQ(fixed["parts"][1]["material"], "Metal");
  EXPECT_EQ(fixed["parts"][1]["structure"], "hollow");
  EXPECT_DOUBLE_EQ(fixed["parts"][1]["density_kg_m3"].get<double>(), 7000.0);
  EXPECT_DOUBLE_EQ(fixed["parts"][1]["wall_thickness_m"].get<double>(), 0.004);
  EXPECT_EQ(fixed["overrides"].size(), 2u);
  const double mass = fixed["object"]["mass_kg"].get<double>();
  EXPECT_LT(mass, 0.8 * plain["object"]["mass_kg"].get<double>());  // a hollow head weighs far less
  // report.json says where the values came from; summary.html lists the corrections.
  const nlohmann::json report = json_of(dir + "/fixed/report.json");
  EXPECT_EQ(report["parts"][1]["sources"]["density"], "user") << report["parts"][1].dump();
  EXPECT_NE(test::read_file(dir + "/fixed/summary.html").find("Corrections applied"), std::string::npos);
  // The folder keeps them as face selections.
  const nlohmann::json kept = json_of(dir + "/fixed/overrides.json");
  EXPECT_EQ(kept["format"], "g2p-overrides");
  EXPECT_EQ(kept["overrides"][0]["faces"], nlohmann::json::parse("[[0, 91]]"));

  // `g2p export` from the plain run's folder with the same file: complete,
  // properties and export run again, and agree with the corrected run.
  r = test::run_tool("export " + test::quote(dir + "/plain") + " --overrides " + test::quote(dir + "/fix.json") +
                     " -o " + test::quote(dir + "/exported"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NEAR(json_of(dir + "/exported/report.json")["object"]["mass_kg"].get<double>(), mass, 1e-9 * mass);
  // `g2p export` from the corrected run's folder: its overrides.json applies again.
  r = test::run_tool("export " + test::quote(dir + "/fixed") + " -o " + test::quote(dir + "/refixed"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NEAR(json_of(dir + "/refixed/report.json")["object"]["mass_kg"].get<double>(), mass, 1e-9 * mass);
  // `g2p properties`, then `g2p export` from its folder.
  r = test::run_tool("properties " + test::quote(dir + "/plain") + " --overrides " + test::quote(dir + "/fix.json") +
                     " -o " + test::quote(dir + "/props"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("7000 kg/m^3 (user)"), std::string::npos) << r.out;
  r = test::run_tool("export " + test::quote(dir + "/props") + " -o " + test::quote(dir + "/props-exported"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out.find("complete "), std::string::npos) << r.out;  // the folder's closed parts and properties
  EXPECT_EQ(r.out.find("properties "), std::string::npos) << r.out;
  EXPECT_NEAR(json_of(dir + "/props-exported/report.json")["object"]["mass_kg"].get<double>(), mass, 1e-9 * mass);
  // `g2p refine` applies the classes to the refined labels.
  r = test::run_tool("refine " + test::quote(dir + "/plain") + " --overrides " + test::quote(dir + "/fix.json") +
                     " -o " + test::quote(dir + "/refined"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(test::read_file(dir + "/refined/faces.csv").find(",Plastic,"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir + "/refined/overrides.json"));
}

TEST(ToolOverrides, ADensityChangeReusesTheClosedParts) {
  const std::string dir = test::scratch_dir("ToolOverridesReuse");
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/run") + " -q --save-intermediates");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double before = json_of(dir + "/run/run.json")["parts"][1]["mass_kg"].get<double>();
  test::write_file(dir + "/denser.json",
                   R"({"format": "g2p-overrides", "version": 1, "overrides": [{"part": 1, "density_kg_m3": 15600}]})");
  r = test::run_tool("export " + test::quote(dir + "/run") + " --overrides " + test::quote(dir + "/denser.json") +
                     " -o " + test::quote(dir + "/out"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("properties "), std::string::npos) << r.out;  // the folder's closed parts, properties again
  EXPECT_EQ(r.out.find("complete "), std::string::npos) << r.out;    // no completion ran
  const nlohmann::json report = json_of(dir + "/out/report.json");
  // Steel (7800 kg/m^3 by the table) twice as dense: twice the mass.
  EXPECT_NEAR(report["parts"][1]["mass_kg"].get<double>(), 2.0 * before, 1e-6 * before) << report.dump();
}

TEST(ToolOverrides, ContentsWeighInTheRunAndEveryFolderThatFollows) {
  // A dead-blow hammer: the steel head a hollow casting half full of steel shot (bulk 4700 kg/m^3).
  const std::string dir = test::scratch_dir("ToolOverridesContents");
  test::write_file(dir + "/shot.json", R"({"format": "g2p-overrides", "version": 1, "overrides": [
    {"part": 1, "structure": "hollow", "wall_thickness_m": 0.003, "contents": {"fill": 0.5, "density_kg_m3": 4700}}]})");
  test::write_file(dir + "/shell.json", R"({"format": "g2p-overrides", "version": 1, "overrides": [
    {"part": 1, "structure": "hollow", "wall_thickness_m": 0.003}]})");
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/shell") + " -q --overrides " +
                                   test::quote(dir + "/shell.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/shot") + " -q --overrides " +
                     test::quote(dir + "/shot.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("correction: part 1: hollow, 3 mm walls, contents 50 % full at 4700 kg/m^3"), std::string::npos)
      << r.err;
  const nlohmann::json shell = json_of(dir + "/shell/report.json")["parts"][1];
  const nlohmann::json shot = json_of(dir + "/shot/report.json")["parts"][1];
  ASSERT_TRUE(shot["contents"].is_object()) << shot.dump();
  const double fill = shot["contents"]["mass_kg"].get<double>();
  EXPECT_GT(fill, 0.0);
  EXPECT_NEAR(shot["mass_kg"].get<double>(), shell["mass_kg"].get<double>() + fill, 1e-9);
  EXPECT_NEAR(shot["material_volume_m3"].get<double>(), shell["material_volume_m3"].get<double>(), 1e-12);
  // The shot lies in the bottom of the head: below the shell's centre of mass.
  EXPECT_LT(shot["contents"]["center_of_mass_m"][2].get<double>(), shell["center_of_mass_m"][2].get<double>());
  EXPECT_NE(test::read_file(dir + "/shot/summary.html").find("50 % full"), std::string::npos);
  const double mass = json_of(dir + "/shot/report.json")["object"]["mass_kg"].get<double>();
  // The folder's overrides.json fills the head again; `g2p properties` writes the contents
  // into its report, and `g2p export` from that folder reads them back.
  r = test::run_tool("export " + test::quote(dir + "/shot") + " -o " + test::quote(dir + "/again"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NEAR(json_of(dir + "/again/report.json")["object"]["mass_kg"].get<double>(), mass, 1e-9 * mass);
  r = test::run_tool("properties " + test::quote(dir + "/shell") + " --overrides " + test::quote(dir + "/shot.json") +
                     " -o " + test::quote(dir + "/props"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = test::run_tool("export " + test::quote(dir + "/props") + " -o " + test::quote(dir + "/props-exported"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const nlohmann::json exported = json_of(dir + "/props-exported/report.json");
  EXPECT_NEAR(exported["object"]["mass_kg"].get<double>(), mass, 1e-9 * mass);
  EXPECT_NEAR(exported["parts"][1]["contents"]["mass_kg"].get<double>(), fill, 1e-9 * fill);
  EXPECT_NEAR(exported["parts"][1]["material_volume_m3"].get<double>(), shell["material_volume_m3"].get<double>(),
              1e-12);

  // A fill asked of the solid wooden handle is not given, and the run says so.
  test::write_file(dir + "/solid.json", R"({"format": "g2p-overrides", "version": 1, "overrides": [
    {"part": 0, "contents": {"fill": 0.5}}]})");
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/solid") + " -q --overrides " +
                     test::quote(dir + "/solid.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: properties: part 0: contents left out: the part is solid and has no cavity (make it "
                       "hollow to fill it"),
            std::string::npos)
      << r.err;
  const nlohmann::json solid = json_of(dir + "/solid/report.json");
  EXPECT_TRUE(solid["parts"][0]["contents"].is_null());
  // The list of corrections applied names the fill and that it was left out.
  const nlohmann::json solid_run = json_of(dir + "/solid/run.json");
  ASSERT_EQ(solid_run["overrides"].size(), 1u) << solid_run["overrides"].dump();
  const std::string applied = solid_run["overrides"][0].get<std::string>();
  EXPECT_EQ(applied.rfind("part 0: contents 50 % full", 0), 0u) << applied;
  EXPECT_NE(applied.find("; contents left out: the part is solid"), std::string::npos) << applied;
  // The handle weighs what it weighs unfilled (the shell run left it alone).
  EXPECT_NEAR(solid["parts"][0]["mass_kg"].get<double>(),
              json_of(dir + "/shell/report.json")["parts"][0]["mass_kg"].get<double>(), 1e-12);
  r = test::run_tool("properties " + test::quote(dir + "/shell") + " --overrides " + test::quote(dir + "/solid.json") +
                     " -o " + test::quote(dir + "/solid-props"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("g2p properties: warning: properties: part 0: contents left out"), std::string::npos) << r.err;
}

TEST(ToolOverrides, ABadFileIsRejectedNamingTheEntryAndNothingIsWritten) {
  const std::string dir = test::scratch_dir("ToolOverridesBad");
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/run") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const struct {
    std::string entries, expected;
  } cases[] = {
      {R"({"part": 5, "class": "Wood"})", "entry 1: part 5 does not exist (the run has 2 parts"},
      {R"({"part": 0, "class": "Wood"}, {"faces": [[100, 200]], "class": "Glass"})",
       "entry 2: face 200 does not exist"},
      {R"({"part": 0, "class": "Mithril"})", "entry 1: unknown class 'Mithril'"},
      {R"({"part": 1, "density_kg_m3": -7800})", "entry 1: 'density_kg_m3' must be a positive density"},
      {R"({"part": 0, "was": {"class": "Metal"}, "class": "Wood"})", "another model or run"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const std::string file = dir + "/bad" + std::to_string(i++) + ".json";
    test::write_file(file, R"({"format": "g2p-overrides", "version": 1, "overrides": [)" + c.entries + "]}");
    for (const std::string command : {"export", "properties"}) {
      const std::string out = dir + "/" + command + std::to_string(i);
      r = test::run_tool(command + " " + test::quote(dir + "/run") + " --overrides " + test::quote(file) + " -o " +
                         test::quote(out));
      EXPECT_EQ(r.exit_code, 2) << command << " " << c.entries << "\n" << r.out << r.err;
      EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
      EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(out)) << out;
    }
    const std::string out = dir + "/run-again" + std::to_string(i);
    r = test::run_tool("run " + hammer() + " -q -o " + test::quote(out) + " --overrides " + test::quote(file));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--overrides " + file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("nothing was written"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
}

// Chains of commands: corrections carried by folders apply once, a folder
// written again without corrections drops its old ones, and a folder whose
// corrections changed after its properties were estimated is refused, not used.
TEST(ToolOverrides, FoldersCarryTheirCorrectionsAndNothingElse) {
  const std::string dir = test::scratch_dir("ToolOverridesChain");
  test::ToolRun r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/run") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  test::write_file(dir + "/plastic.json",
                   R"({"format": "g2p-overrides", "version": 1, "overrides": [{"part": 0, "class": "Plastic"}]})");
  test::write_file(dir + "/denser.json",
                   R"({"format": "g2p-overrides", "version": 1, "overrides": [{"part": 1, "density_kg_m3": 15600}]})");
  // A properties folder made with a class change; a density change on top keeps its closed parts.
  r = test::run_tool("properties " + test::quote(dir + "/run") + " --overrides " + test::quote(dir + "/plastic.json") +
                     " -o " + test::quote(dir + "/props"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = test::run_tool("export " + test::quote(dir + "/props") + " --overrides " + test::quote(dir + "/denser.json") +
                     " -o " + test::quote(dir + "/out"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("properties "), std::string::npos) << r.out;  // the folder's closed parts, properties again
  const nlohmann::json report = json_of(dir + "/out/report.json");
  EXPECT_EQ(report["parts"][0]["material"], "Plastic");
  EXPECT_DOUBLE_EQ(report["parts"][1]["density_kg_m3"].get<double>(), 15600.0);
  // The carried corrections once each: the class change and the density.
  EXPECT_EQ(json_of(dir + "/out/overrides.json")["overrides"].size(), 2u)
      << test::read_file(dir + "/out/overrides.json");

  // `g2p properties` into the same folder again, without corrections: the old ones go.
  r = test::run_tool("properties " + test::quote(dir + "/run") + " -o " + test::quote(dir + "/props") + " --overwrite");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_FALSE(fs::exists(dir + "/props/overrides.json"));
  EXPECT_EQ(json_of(dir + "/props/report.json")["parts"][0]["material"], "Wood");

  // `g2p complete --overrides` from a kept run folder records them in the new folder; a folder
  // whose own corrections changed after its report was made closes its parts again, not the stale ones.
  r = test::run_tool("run " + hammer() + " -o " + test::quote(dir + "/kept") + " -q --save-intermediates");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_tool("complete " + test::quote(dir + "/kept") + " --overrides " + test::quote(dir + "/plastic.json") +
                     " -o " + test::quote(dir + "/kept-complete"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(dir + "/kept-complete/overrides.json"));
  test::write_file(dir + "/kept/overrides.json", test::read_file(dir + "/plastic.json"));
  r = test::run_tool("export " + test::quote(dir + "/kept") + " -o " + test::quote(dir + "/kept-out"));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("changes classes its faces.csv does not have"), std::string::npos) << r.err;
  EXPECT_EQ(json_of(dir + "/kept-out/report.json")["parts"][0]["material"], "Plastic");
}

}  // namespace
}  // namespace g2p
