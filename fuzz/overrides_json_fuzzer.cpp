// libFuzzer target: overrides files (docs/pipeline.md#overrides), as
// summary.html writes them and `--overrides` reads them, on arbitrary bytes.
// What parses must write back to the same text, and resolving and applying it
// on a small labelled grid (4 x 4 squares, two classes, two parts) must leave
// every face a class of the table, every face in exactly one part, and the
// estimator's values positive; the same corrections as face selections
// (a folder's overrides.json) must give the same classes and properties.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "g2p/overrides.h"
#include "model_invariants.h"

namespace {

struct Grid {
  g2p::Mesh mesh;
  g2p::FaceGraph graph;
  std::vector<int> labels, face_part;
  std::vector<g2p::Part> parts;
};

const Grid& grid() {
  static const Grid g = [] {
    Grid out;
    constexpr int n = 4;
    for (int y = 0; y <= n; ++y)
      for (int x = 0; x <= n; ++x) out.mesh.positions.emplace_back(0.1f * x, 0.1f * y, 0.f);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const int a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
        out.mesh.triangles.emplace_back(a, b, d);
        out.mesh.triangles.emplace_back(a, d, c);
        out.labels.push_back(x < n / 2 ? 0 : 5);
        out.labels.push_back(x < n / 2 ? 0 : 5);
      }
    out.graph = *g2p::build_face_graph(out.mesh);
    out.parts = g2p::partition(out.mesh, out.graph, out.labels, out.face_part);
    return out;
  }();
  return g;
}

class Table final : public g2p::PropertyEstimator {
 public:
  g2p::Result<g2p::PartProperties> estimate(const g2p::PropertyInput& in) const override {
    g2p::PartProperties p;
    p.label = in.part->label;
    p.density_kg_m3 = p.density_min_kg_m3 = p.density_max_kg_m3 = 1000.0;
    return p;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  g2p::Result<g2p::Overrides> o = g2p::parse_overrides(text, table, "input");
  if (!o.ok()) return 0;
  const std::string written = g2p::overrides_json(*o, table);
  g2p::Result<g2p::Overrides> again = g2p::parse_overrides(written, table, "written");
  if (!again.ok() || g2p::overrides_json(*again, table) != written) g2p::fuzz::violated("overrides: no round trip");

  Grid g = grid();
  g2p::Result<g2p::ResolvedOverrides> r = g2p::resolve_overrides(*o, g.mesh.num_faces(), g.parts, g.labels, table);
  if (!r.ok()) return 0;
  if (!g2p::apply_class_overrides(*r, g.mesh, g.graph, g.labels, g.face_part, g.parts, table).ok())
    g2p::fuzz::violated("overrides: resolved overrides did not apply");
  std::vector<int> seen(static_cast<std::size_t>(g.mesh.num_faces()), 0);
  for (const g2p::Part& p : g.parts)
    for (int f : p.faces) ++seen[static_cast<std::size_t>(f)];
  for (std::size_t f = 0; f < seen.size(); ++f) {
    if (seen[f] != 1) g2p::fuzz::violated("overrides: a face in no part or in two");
    if (!table.valid_label(g.labels[f])) g2p::fuzz::violated("overrides: a face outside the table");
  }
  Table base;
  const std::unique_ptr<g2p::PropertyEstimator> e = g2p::make_overriding_estimator(base, *r);
  for (const g2p::Part& p : g.parts) {
    g2p::PropertyInput in{&g.mesh, &p, nullptr, &table};
    g2p::Result<g2p::PartProperties> props = e->estimate(in);
    if (!props.ok() || !(props->density_kg_m3 > 0) ||
        (props->structure == g2p::Structure::kHollow && !(props->wall_thickness_m > 0)))
      g2p::fuzz::violated("overrides: an estimate without a positive density or wall");
  }
  // The face selections mean the same on the original labels.
  const Grid& fresh = grid();
  Grid h = fresh;
  g2p::Result<g2p::ResolvedOverrides> faces =
      g2p::resolve_overrides(g2p::as_face_selections(*r), h.mesh.num_faces(), h.parts, h.labels, table);
  if (!faces.ok() || !g2p::apply_class_overrides(*faces, h.mesh, h.graph, h.labels, h.face_part, h.parts, table).ok() ||
      h.labels != g.labels)
    g2p::fuzz::violated("overrides: face selections differ from the overrides");
  const std::unique_ptr<g2p::PropertyEstimator> e2 = g2p::make_overriding_estimator(base, *faces);
  for (std::size_t i = 0; i < g.parts.size(); ++i) {
    g2p::PropertyInput a{&g.mesh, &g.parts[i], nullptr, &table}, b{&h.mesh, &h.parts[i], nullptr, &table};
    g2p::Result<g2p::PartProperties> pa = e->estimate(a), pb = e2->estimate(b);
    if (!pa.ok() || !pb.ok() || pa->structure != pb->structure || pa->wall_thickness_m != pb->wall_thickness_m ||
        pa->density_kg_m3 != pb->density_kg_m3)
      g2p::fuzz::violated("overrides: face selections give other properties than the overrides");
  }
  return 0;
}
