// summary.html: one page a person opens to check a run at a glance: the
// views, the segmented and projected labels, the parts with their masses, the
// stages' times and any warnings. Plain HTML and CSS, no scripts.
#include <cstdio>
#include <sstream>
#include <string>

#include "g2p/pipeline.h"

namespace g2p {
namespace {

std::string escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string number(double v, const char* format = "%.4g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void figure(std::ostringstream& h, const std::string& src, const std::string& caption) {
  h << "<figure><a href=\"" << src << "\"><img src=\"" << src << "\" alt=\"" << escape(caption) << "\"></a><figcaption>"
    << escape(caption) << "</figcaption></figure>\n";
}

// Where the object's size came from, in the user's terms.
std::string size_source(const ImportInfo& info) {
  if (info.scale_source == "height") return "--height";
  if (info.scale_source == "longest-side") return "--longest-side";
  if (info.scale_source == "unit") return "--unit";
  return info.looks_normalised ? "the file, which looks normalised: give --height or --longest-side" : "the file";
}

}  // namespace

std::string summary_html(const PipelineResult& r, const PipelineOptions& o) {
  const MassProperties& m = r.properties.object;
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape(r.asset.name)
    << " - libg2p</title>\n"
    << "<style>body{font-family:sans-serif;margin:2em;max-width:1200px}figure{display:inline-block;margin:0 1em 1em 0;"
       "vertical-align:top}img{width:360px;border:1px solid #ccc}table{border-collapse:collapse;margin-bottom:1.5em}"
       "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}td:first-child,th:first-child,td.l{text-align:"
       "left}.sw{display:inline-block;width:1em;height:1em;vertical-align:middle;margin-right:.4em;border:1px solid "
       "#555}.warn{color:#a40000}</style></head><body>\n";
  h << "<h1>" << escape(r.asset.name) << "</h1>\n<p>" << escape(r.model.info.path) << ": " << r.model.mesh.num_faces()
    << " triangles, " << r.views.size() << " views, " << r.projection.parts.size() << " parts. Total mass <b>"
    << number(m.mass_kg) << " kg</b> (plausible range " << number(r.properties.mass_min_kg) << " to "
    << number(r.properties.mass_max_kg) << " kg), centre of mass (" << number(m.center_of_mass.x()) << ", "
    << number(m.center_of_mass.y()) << ", " << number(m.center_of_mass.z()) << ") m. Size "
    << number(r.properties.size.extent_m.x()) << " x " << number(r.properties.size.extent_m.y()) << " x "
    << number(r.properties.size.extent_m.z()) << " m (height last; scale from " << escape(size_source(r.model.info))
    << "). Run time " << number(r.seconds, "%.2f") << " s.</p>\n";
  if (!r.warnings.empty()) {
    h << "<ul class=\"warn\">\n";
    for (const std::string& w : r.warnings) h << "<li>" << escape(w) << "</li>\n";
    h << "</ul>\n";
  }
  h << "<h2>Views and labels</h2>\n";
  figure(h, "views/contact_sheet.png", "rendered views");
  figure(h, "segmented/contact_sheet.png", "segmented (per pixel)");
  figure(h, "projected/contact_sheet.png", "projected onto the faces (final labels)");
  figure(h, "segmented/legend.png", "classes");

  h << "<h2>Parts</h2>\n<table><tr><th>part</th><th>material</th><th>faces</th><th>area (m&sup2;)</th>"
       "<th>closed</th><th>volume (cm&sup3;)</th><th>density (kg/m&sup3;)</th><th>structure</th><th>mass (kg)</th>"
       "</tr>\n";
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) {
    const Part& p = r.projection.parts[i];
    const bool known = r.table.valid_label(p.label);
    h << "<tr><td>" << i << "</td><td class=\"l\">";
    if (known) {
      const auto& c = r.table[p.label].color;
      char rgb[16];
      std::snprintf(rgb, sizeof rgb, "#%02x%02x%02x", c[0], c[1], c[2]);
      h << "<span class=\"sw\" style=\"background:" << rgb << "\"></span>" << escape(r.table[p.label].name);
    } else {
      h << "Unknown";
    }
    h << "</td><td>" << p.faces.size() << "</td><td>" << number(p.area_m2) << "</td>";
    if (i < r.completion.parts.size() && i < r.properties.parts.size()) {
      const CompletedPart& c = r.completion.parts[i];
      const PartReport& pr = r.properties.parts[i];
      h << "<td>" << (c.ok ? "yes" : "<span class=\"warn\">no</span>") << "</td><td>"
        << number(c.checks.volume_m3 * 1e6) << "</td><td>" << number(pr.properties.density_kg_m3) << "</td><td>"
        << to_string(pr.properties.structure);
      if (pr.properties.structure == Structure::kHollow && pr.properties.wall_thickness_m > 0)
        h << ", " << number(pr.properties.wall_thickness_m * 1e3) << " mm walls";
      h << "</td><td>" << number(pr.mass.mass_kg) << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";

  h << "<h2>Stages</h2>\n<table><tr><th>stage</th><th>backend</th><th>time (s)</th><th>peak memory (MiB)</th>"
       "<th>notes</th></tr>\n";
  for (const StageReport& s : r.stages) {
    h << "<tr><td>" << to_string(s.stage) << "</td><td class=\"l\">" << escape(s.backend) << "</td><td>"
      << number(s.seconds, "%.2f") << "</td><td>" << number(static_cast<double>(s.peak_rss_bytes) / 1048576.0, "%.0f")
      << "</td><td class=\"l\">";
    if (!s.ok) h << "<span class=\"warn\">failed: " << escape(s.error) << "</span> ";
    for (const std::string& n : s.notes) h << escape(n) << "<br>";
    h << "</td></tr>\n";
  }
  h << "</table>\n<h2>Files</h2>\n<ul>\n";
  for (const std::string& f : o.formats) {
    const std::string ext = f == "mjcf" ? ".xml" : "." + f;
    h << "<li><a href=\"" << escape(r.asset.name + ext) << "\">" << escape(r.asset.name + ext) << "</a></li>\n";
  }
  h << "<li><a href=\"report.json\">report.json</a> (per-part properties), <a href=\"run.json\">run.json</a>, "
       "<a href=\"faces.csv\">faces.csv</a>, <a href=\"labelled.ply\">labelled.ply</a></li>\n</ul>\n"
       "<p>Written by libg2p (Gen2Physics).</p></body></html>\n";
  return h.str();
}

}  // namespace g2p
