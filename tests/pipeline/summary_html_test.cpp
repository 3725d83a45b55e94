// summary.html as a person reads it (issue #35): every view shown where the
// object is, a one-line legend, the stages in plain words with the
// developers' notes folded away, a banner for what needs attention, and the
// 3D view's data, simplified for a model of a million triangles. The page in
// a real browser: tests/tools/summary_browser_test.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <nlohmann/json.hpp>
#include <regex>

#include "g2p/pipeline.h"
#include "support/large_result.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// The bytes of base64 text (RFC 4648, with padding).
std::string base64_bytes(const std::string& text) {
  static const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<unsigned>(alphabet.find(c));
    count += 6;
    if (count >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xFF));
    }
  }
  return out;
}

PipelineOptions quick_options() {
  PipelineOptions o;
  o.views.num_views = 6;
  o.views.width = o.views.height = 160;
  return o;
}

const PipelineResult& hammer_run() {
  static const PipelineResult result = [] {
    Result<PipelineResult> r = Pipeline(quick_options()).run_file(test::source_path("examples/data/hammer.obj"));
    if (!r.ok()) throw std::runtime_error(r.status().to_string());
    return std::move(*r);
  }();
  return result;
}

// The 3D view's data, or null when this libg2p was built without the viewer.
nlohmann::json viewer_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"g2p-model\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) return nullptr;
  const std::size_t end = html.find("</script>", begin);
  return nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
}

std::string without_details(std::string html) {
  return std::regex_replace(html, std::regex("<details>[\\s\\S]*?</details>"), "");
}

TEST(SummaryHtml, ShowsEveryViewWhereTheObjectIsWithAOneLineLegend) {
  const std::string html = summary_html(hammer_run(), quick_options());
  for (int i = 0; i < 6; ++i) {
    const std::string n = "0" + std::to_string(i);
    EXPECT_NE(html.find("views/view_" + n + "_rgb.png"), std::string::npos) << i;
    EXPECT_NE(html.find("segmented/view_" + n + "_labels.png"), std::string::npos) << i;
    EXPECT_NE(html.find("projected/view_" + n + "_labels.png"), std::string::npos) << i;
  }
  EXPECT_EQ(html.find("contact_sheet.png"), std::string::npos);
  EXPECT_EQ(html.find("legend.png"), std::string::npos);
  // View 0 looks down on the hammer, which fills a sliver of the 160 px image:
  // the page magnifies it (tiles are 120 px; a width over 160 px is a zoom).
  const std::regex first_image("view_00_rgb.png\" alt=\"view 0\" style=\"width:([0-9.]+)px");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(html, m, first_image));
  EXPECT_GT(std::stod(m[1]), 1.5 * 160);
  // One legend line with all 12 classes, the absent ones greyed.
  const std::size_t legend = html.find("<div class=\"legend\">");
  ASSERT_NE(legend, std::string::npos);
  const std::string line = html.substr(legend, html.find("</div>", legend) - legend);
  EXPECT_EQ(std::count(line.begin(), line.end(), '#'), 12);
  EXPECT_EQ(std::regex_search(line, std::regex("class=\"absent\"><span class=\"sw\"[^>]*></span>Wood")), false);
  EXPECT_TRUE(std::regex_search(line, std::regex("class=\"absent\"><span class=\"sw\"[^>]*></span>Glass")));
}

TEST(SummaryHtml, TellsWhatEachStageDidInPlainWords) {
  const PipelineResult& r = hammer_run();
  const std::string html = summary_html(r, quick_options());
  EXPECT_NE(html.find("Closed 2 of 2 parts into watertight volumes"), std::string::npos);
  EXPECT_NE(html.find("Gave every pixel of every view one of 12 material classes"), std::string::npos);
  // The stages' own notes (grid sizes, timings) stay, folded under "details".
  const std::string visible = without_details(html);
  std::size_t notes = 0;
  for (const StageReport& s : r.stages)
    for (const std::string& note : s.notes) {
      ++notes;
      EXPECT_EQ(visible.find(note), std::string::npos) << note;
    }
  EXPECT_GT(notes, 3u);
  EXPECT_EQ(html.find("Check before use"), std::string::npos);  // nothing to warn about
}

TEST(SummaryHtml, PutsWarningsLeftOutPartsAndImplausibleTotalsInABanner) {
  PipelineResult r = hammer_run();
  r.warnings.push_back("export: 1 of 2 parts are left out of the asset (no closed volume or no mass): part 1");
  r.completion.parts[1].ok = false;
  r.asset.parts.erase(r.asset.parts.begin() + 1);
  r.properties.mass_max_kg = r.properties.object.mass_kg / 2;
  StageReport* refine = nullptr;
  for (StageReport& s : r.stages)
    if (s.stage == Stage::kRefine) refine = &s;
  ASSERT_NE(refine, nullptr);
  refine->ok = false;
  refine->error = "the model server did not answer";
  const std::string html = summary_html(r, quick_options());
  const std::size_t banner = html.find("<div class=\"banner\"");
  ASSERT_NE(banner, std::string::npos);
  EXPECT_LT(banner, html.find("<h2>Parts</h2>"));  // at the top
  const std::string text = html.substr(banner, html.find("</div>", banner) - banner);
  EXPECT_NE(text.find("1 of 2 parts are left out"), std::string::npos);
  EXPECT_NE(text.find("outside its own plausible range"), std::string::npos);
  EXPECT_NE(text.find("refine (smooth) failed and the run went on without it: the model server did not answer"),
            std::string::npos);
  const nlohmann::json data = viewer_data(html);
  if (data.is_null())
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  EXPECT_EQ(data["parts"][1]["left_out"], "it could not be closed into a volume");
  EXPECT_FALSE(data["parts"][0].contains("left_out"));
}

TEST(SummaryHtml, CarriesEachPartsGeometryHullsAndPropertiesForThe3DView) {
  const PipelineResult& r = hammer_run();
  const std::string html = summary_html(r, quick_options());
  const nlohmann::json data = viewer_data(html);
  if (data.is_null())
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  EXPECT_EQ(data["format"], "g2p-summary-view");
  EXPECT_EQ(data["triangles"], 104);
  EXPECT_EQ(data["triangles_drawn"], 104);
  EXPECT_NE(html.find("all 104 triangles drawn"), std::string::npos);
  ASSERT_EQ(data["parts"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const nlohmann::json& p = data["parts"][i];
    const std::size_t faces = p["faces"];
    EXPECT_EQ(p["faces_drawn"], faces);
    // base64 of uint16 indices (6 bytes a triangle) and one sRGB colour a triangle.
    EXPECT_EQ(p["visual"]["index_bits"], 16);
    EXPECT_EQ(p["visual"]["indices"].get<std::string>().size(), 4 * ((6 * faces + 2) / 3));
    EXPECT_EQ(p["visual"]["look"].get<std::string>().size(), 4 * faces);
    // Positions quantized to 16 bits over the part's bounds: decoded, they
    // span the part's visual mesh's bounds to within half a step.
    const std::string q = base64_bytes(p["visual"]["positions"].get<std::string>());
    ASSERT_EQ(q.size() % 6, 0u);
    Eigen::AlignedBox3d drawn;
    for (std::size_t v = 0; v < q.size() / 6; ++v) {
      Eigen::Vector3d x;
      for (int a = 0; a < 3; ++a) {
        std::uint16_t code = 0;
        std::memcpy(&code, q.data() + 6 * v + 2 * static_cast<std::size_t>(a), 2);
        x[a] = p["visual"]["position_min"][a].get<double>() + code * p["visual"]["position_step"][a].get<double>();
      }
      drawn.extend(x);
    }
    Eigen::AlignedBox3d visual;
    for (const Eigen::Vector3f& v : r.asset.parts[i].visual.positions) visual.extend(v.cast<double>());
    for (int a = 0; a < 3; ++a) {
      const double half_step = 0.5 * p["visual"]["position_step"][a].get<double>() + 1e-7;
      EXPECT_NEAR(drawn.min()[a], visual.min()[a], half_step) << "part " << i;
      EXPECT_NEAR(drawn.max()[a], visual.max()[a], half_step) << "part " << i;
    }
    EXPECT_EQ(p["hulls"].size(), r.asset.parts[i].collision.hulls.size());
    EXPECT_GT(p["hulls"].size(), 0u);
    EXPECT_NEAR(p["mass_kg"].get<double>(), r.properties.parts[i].mass.mass_kg, 1e-12);
    EXPECT_EQ(p["material"], r.table[r.projection.parts[i].label].name);
    EXPECT_EQ(p["name"], r.asset.parts[i].name);
  }
  EXPECT_NEAR(data["center_of_mass_m"][2].get<double>(), r.properties.object.center_of_mass.z(), 1e-12);
  // Nothing in the data may end its <script> early.
  EXPECT_EQ(html.find("</", html.find("id=\"g2p-model\">")), html.find("</script>", html.find("id=\"g2p-model\">")));
}

TEST(SummaryHtml, SimplifiesWhatItDrawsOfAMillionTriangleModel) {
  const PipelineResult r = test::large_grid_result();
  ASSERT_GT(r.model.mesh.num_faces(), 1200000);
  const auto start = std::chrono::steady_clock::now();
  const std::string html = summary_html(r);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const nlohmann::json data = viewer_data(html);
  if (data.is_null())
    GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";
  const std::size_t drawn = data["triangles_drawn"];
  EXPECT_LE(drawn, 200000u);
  EXPECT_GT(drawn, 50000u);  // still a detailed picture
  EXPECT_EQ(data["triangles"], r.model.mesh.num_faces());
  EXPECT_NE(html.find("the surface is simplified to"), std::string::npos);
  EXPECT_LT(html.size(), 12u << 20);  // about 25 bytes per drawn triangle plus the viewer
  // Both parts keep their share.
  EXPECT_GT(data["parts"][0]["faces_drawn"].get<std::size_t>(), drawn / 3);
  EXPECT_GT(data["parts"][1]["faces_drawn"].get<std::size_t>(), drawn / 3);
  std::printf("summary.html of %d triangles: %zu drawn, %.1f MB, %.2f s\n", r.model.mesh.num_faces(), drawn,
              html.size() / 1e6, seconds);
}

}  // namespace
}  // namespace g2p
