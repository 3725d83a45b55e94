// summary.html in a real browser (headless Chromium, tests/validators/
// summary_browser.js): the 3D view draws the object, each control changes the
// picture, hovering shows a part's details, the page never asks the network,
// and without WebGL it says so and keeps its static content. Labelled
// "browser" (ctest -LE browser leaves them out); each skips, saying what is
// missing, where node, playwright-core or Chromium is not installed.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "g2p/pipeline.h"
#include "support/large_result.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

// The hammer through `g2p run`, once per test process.
const std::string& hammer_page() {
  static const std::string page = [] {
    const std::string dir = test::scratch_dir("SummaryBrowser") + "/hammer";
    const test::ToolRun r = test::run_tool("run " + test::quote(test::source_path("examples/data/hammer.obj")) +
                                           " -o " + test::quote(dir) + " --overwrite --views 6 --resolution 160");
    if (r.exit_code != 0) throw std::runtime_error("g2p run failed: " + r.err);
    return dir + "/summary.html";
  }();
  return page;
}

bool has_viewer(const std::string& page) { return test::read_file(page).find("id=\"g2p-model\"") != std::string::npos; }

#define SKIP_WITHOUT_BROWSER(v) \
  if (!(v).available)           \
    GTEST_SKIP() << "no browser test: " << (v).missing << " is missing (scripts/install-deps.sh installs it)";

TEST(SummaryBrowser, The3DViewDrawsTheHammerAndEveryControlChangesThePicture) {
  const std::string& page = hammer_page();
  if (!has_viewer(page))
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  const std::string shot = fs::path(page).parent_path().string() + "/page.png";
  const test::ValidatorRun v = test::run_summary_browser(page, "--screenshot " + test::quote(shot));
  SKIP_WITHOUT_BROWSER(v);
  ASSERT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  const nlohmann::json j = nlohmann::json::parse(v.run.out);
  EXPECT_EQ(j["checks"].size(), 6u) << j.dump(1);
  EXPECT_GT(j["object_fraction"].get<double>(), 0.01);
  EXPECT_NE(j["hover"].get<std::string>().find("part_"), std::string::npos);
  EXPECT_TRUE(fs::exists(shot));
}

// The correction round trip: a person picks the hammer's handle in the page,
// makes it hollow plastic of 1100 kg/m^3, 30 % full of water, says the object
// is a screwdriver, and downloads the overrides; `g2p export` applies them to
// the run's folder, and report.json says so.
TEST(SummaryBrowser, ACorrectionMadeInThePageIsAppliedByTheCli) {
  const std::string& page = hammer_page();
  if (!has_viewer(page))
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  const std::string run = fs::path(page).parent_path().string();
  const std::string dir = test::scratch_dir("SummaryBrowserCorrection");
  const nlohmann::json before = nlohmann::json::parse(test::read_file(run + "/run.json"));
  ASSERT_EQ(before["parts"][0]["material"], "Wood");
  const test::ValidatorRun v = test::run_summary_browser(
      page, "--correct 0:Plastic:1100:30 --object screwdriver --download " + test::quote(dir + "/overrides.json"));
  SKIP_WITHOUT_BROWSER(v);
  ASSERT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  const nlohmann::json fix = nlohmann::json::parse(test::read_file(dir + "/overrides.json"));
  EXPECT_EQ(fix["format"], "g2p-overrides");
  EXPECT_EQ(fix["object"], "screwdriver") << fix.dump();
  ASSERT_EQ(fix["overrides"].size(), 1u) << fix.dump();
  EXPECT_EQ(fix["overrides"][0]["part"], 0);
  EXPECT_EQ(fix["overrides"][0]["was"]["class"], "Wood");
  EXPECT_DOUBLE_EQ(fix["overrides"][0]["contents"]["fill"].get<double>(), 0.3) << fix.dump();
  EXPECT_EQ(fix["overrides"][0]["structure"], "hollow");
  const test::ToolRun r = test::run_tool("export " + test::quote(run) + " --overrides " +
                                         test::quote(dir + "/overrides.json") + " -o " + test::quote(dir + "/fixed"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("'screwdriver'"), std::string::npos) << r.out;  // the correction of what it is, said
  const nlohmann::json report = nlohmann::json::parse(test::read_file(dir + "/fixed/report.json"));
  const nlohmann::json* handle = nullptr;
  for (const nlohmann::json& p : report["parts"])
    if (p["material"] == "Plastic") handle = &p;
  ASSERT_NE(handle, nullptr) << report.dump(1);
  EXPECT_DOUBLE_EQ((*handle)["density_kg_m3"].get<double>(), 1100.0);
  EXPECT_EQ((*handle)["sources"]["density"], "user");
  ASSERT_TRUE((*handle)["contents"].is_object()) << handle->dump(1);  // made hollow: the water weighs
  EXPECT_DOUBLE_EQ((*handle)["contents"]["density_kg_m3"].get<double>(), 1000.0);
  EXPECT_GT((*handle)["contents"]["mass_kg"].get<double>(), 0.0);
  EXPECT_EQ(report["parts"].size(), before["parts"].size());
}

// The check itself: a view that shows nothing must fail it.
TEST(SummaryBrowser, ABlankViewFailsTheCheck) {
  const std::string& page = hammer_page();
  if (!has_viewer(page))
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  std::string html = test::read_file(page);
  html.replace(html.find("</style>"), 8, "#g2p-3d canvas{opacity:0}</style>");
  const std::string blank = fs::path(page).parent_path().string() + "/blank.html";
  test::write_file(blank, html);
  const test::ValidatorRun v = test::run_summary_browser(blank);
  SKIP_WITHOUT_BROWSER(v);
  EXPECT_EQ(v.run.exit_code, 1) << v.run.out << v.run.err;
  EXPECT_NE(v.run.err.find("the 3D view is blank"), std::string::npos) << v.run.err;
}

TEST(SummaryBrowser, WithoutWebGLThePageSaysSoAndKeepsItsTables) {
  const std::string& page = hammer_page();
  if (!has_viewer(page))
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  const test::ValidatorRun v = test::run_summary_browser(page, "--no-webgl");
  SKIP_WITHOUT_BROWSER(v);
  ASSERT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
}

// 1.2M triangles: the page opens and draws its simplified surface.
TEST(SummaryBrowser, AMillionTriangleModelOpensAndDraws) {
  const std::string html = summary_html(test::large_grid_result());
  if (html.find("id=\"g2p-model\"") == std::string::npos)
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  const std::string page = test::scratch_dir("SummaryBrowserLarge") + "/summary.html";
  test::write_file(page, html);
  const test::ValidatorRun v = test::run_summary_browser(page, "--draw-only");
  SKIP_WITHOUT_BROWSER(v);
  ASSERT_EQ(v.run.exit_code, 0) << v.run.out << v.run.err;
  const nlohmann::json j = nlohmann::json::parse(v.run.out);
  // How quick it is goes to the log, not into a bound (docs/testing.md: no
  // timed tests); the simplification itself is SummaryHtml.SimplifiesWhatItDrawsOfAMillionTriangleModel.
  std::printf("1.2M-triangle page: ready in %.2f s, %.0f ms a frame\n", j["ready_s"].get<double>(),
              j["frame_ms"].get<double>());
}

}  // namespace
}  // namespace g2p
