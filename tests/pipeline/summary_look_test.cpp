// summary.html's 3D view shows the input's own look (#50): with "input's own
// look" on, a face has its material's base colour times its vertex colours,
// as the renderer and glTF's COLOR_0 have it. The page is given one sRGB
// colour per drawn face (summary_html_test.cpp checks its size); this checks
// the colours.
#include <gtest/gtest.h>

#include <cstdint>

#include <cmath>
#include <nlohmann/json.hpp>

#include "g2p/pipeline.h"
#include "support/test_data.h"

namespace g2p {
namespace {

// The look colours of every part, in drawing order, as sRGB bytes; empty when
// this libg2p was built without the 3D view.
std::vector<std::string> look_bytes(const PipelineResult& r) {
  const std::string html = summary_html(r);
  const std::string open = "<script type=\"application/json\" id=\"g2p-model\">";
  const std::size_t begin = html.find(open);
  if (begin == std::string::npos) return {};
  const std::size_t end = html.find("</script>", begin);
  const nlohmann::json data = nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
  std::vector<std::string> out;
  for (const auto& p : data["parts"]) {
    const std::string b64 = p["visual"]["look"];
    std::string bytes;  // base64 decoded
    int bits = 0;
    std::uint32_t value = 0;  // the last 24 bits read; older ones are already decoded
    for (char c : b64) {
      const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
      const std::size_t k = alphabet.find(c);
      if (k == std::string::npos) continue;
      value = ((value << 6) | static_cast<std::uint32_t>(k)) & 0xffffffu, bits += 6;
      if (bits >= 8) bits -= 8, bytes.push_back(static_cast<char>((value >> bits) & 0xff));
    }
    out.push_back(bytes);
  }
  return out;
}

TEST(SummaryLook, The3DViewsOwnLookMultipliesTheMaterialByTheVertexColours) {
  PipelineOptions o;
  o.views.num_views = 6;
  o.views.width = o.views.height = 160;
  Result<PipelineResult> run = Pipeline(o).run_file(test::source_path("examples/data/hammer.obj"));
  ASSERT_TRUE(run.ok()) << run.status().to_string();
  PipelineResult& r = *run;
  ASSERT_FALSE(r.model.mesh.has_colors());
  const std::vector<std::string> plain = look_bytes(r);
  if (plain.empty()) GTEST_SKIP() << "libg2p was built without the 3D view (three.js missing: scripts/install-deps.sh)";

  // Every vertex red at half strength in green: each face's colour is its
  // material's base colour times (1, 0.5, 0).
  r.model.mesh.colors.assign(r.model.mesh.positions.size(), Eigen::Vector4f(1.f, 0.5f, 0.f, 1.f));
  const std::vector<std::string> coloured = look_bytes(r);
  ASSERT_EQ(coloured.size(), plain.size());
  std::size_t faces = 0;
  for (std::size_t p = 0; p < plain.size(); ++p) {
    ASSERT_EQ(coloured[p].size(), plain[p].size());
    for (std::size_t i = 0; i + 2 < plain[p].size(); i += 3, ++faces) {
      auto linear = [](char byte) {  // IEC 61966-2-1
        const float c = static_cast<unsigned char>(byte) / 255.f;
        return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
      };
      EXPECT_NEAR(linear(coloured[p][i]), linear(plain[p][i]), 0.01f) << "part " << p << " face " << i / 3;
      EXPECT_NEAR(linear(coloured[p][i + 1]), 0.5f * linear(plain[p][i + 1]), 0.01f) << "part " << p;
      EXPECT_EQ(static_cast<unsigned char>(coloured[p][i + 2]), 0) << "part " << p;
    }
  }
  EXPECT_EQ(faces, static_cast<std::size_t>(r.model.mesh.num_faces()));
}

}  // namespace
}  // namespace g2p
