// Private: the interactive 3D view of summary.html (issue #35). The page
// carries the object's geometry as JSON and the viewer script (three.js,
// bundled at build time from libg2p/web/), so it works offline from file://.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "g2p/pipeline.h"

namespace g2p::detail {

// Most triangles the view draws for the object's surface; larger inputs are
// simplified (view_mesh) and the page says so. 30 to 40 bytes a drawn triangle in the page.
constexpr std::size_t kViewerTriangleBudget = 200000;

// Whether this libg2p was built with the viewer script (three.js and esbuild
// were installed in libg2p/web/node_modules when it was built).
bool summary_viewer_built();

// "#rrggbb" of an sRGB colour.
std::string css_color(const std::array<std::uint8_t, 3>& rgb);

struct SummaryViewer {
  std::string section;  // the 3D view's place on the page, or a line saying why there is none
  std::string scripts;  // the geometry (JSON) and the viewer script, for the end of <body>
};

SummaryViewer summary_viewer(const PipelineResult& result, std::size_t max_triangles = kViewerTriangleBudget);

}  // namespace g2p::detail
