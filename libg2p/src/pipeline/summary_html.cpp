// summary.html: one page a person opens to check a run at a glance: what
// needs their attention first, the object in 3D (summary_viewer.cpp), the
// parts with their masses, every view with its labels, what each stage did in
// plain words, and the files. Without JavaScript or WebGL the page is the same
// less the 3D view.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>

#include "g2p/pipeline.h"
#include "g2p/segment.h"
#include "pipeline/summary_viewer.h"

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

std::string two_digits(std::size_t i) { return (i < 10 ? "0" : "") + std::to_string(i); }

// Where the object's size came from, in the user's terms.
std::string size_source(const ImportInfo& info) {
  if (info.scale_source == "height") return "--height";
  if (info.scale_source == "longest-side") return "--longest-side";
  if (info.scale_source == "unit") return "--unit";
  if (info.scale_source == "kind")
    return "the object's kind: the file looked normalised; give --height or --longest-side for the real size";
  return info.looks_normalised ? "the file, which looks normalised: give --height or --longest-side" : "the file";
}

const char* kStyle =
    "body{font-family:sans-serif;margin:1.5em 2em;max-width:1280px;color:#222}"
    "table{border-collapse:collapse;margin-bottom:1.5em}"
    "td,th{border:1px solid #ccc;padding:3px "
    "8px;text-align:right}td:first-child,th:first-child,td.l,th.l{text-align:left}"
    ".sw{display:inline-block;width:.9em;height:.9em;vertical-align:middle;margin-right:.35em;border:1px solid #555}"
    ".warn{color:#a40000}.note{color:#555;font-size:.9em}"
    ".banner{border:2px solid #c0392b;background:#fdecea;padding:.5em 1em;margin:1em 0}"
    ".banner h2{margin:.2em 0;font-size:1.1em;color:#a40000}.banner ul{margin:.3em 0;padding-left:1.2em}"
    ".corrections{border:2px solid #1f5fbf;background:#eaf1fb;padding:.5em 1em;margin:1em 0}"
    ".corrections h2{margin:.2em 0;font-size:1.1em;color:#1f3f8f}"
    ".legend{display:flex;flex-wrap:wrap;gap:.2em 1.1em;font-size:.9em;margin:.3em 0 1em}.legend .absent{color:#999}"
    ".views{display:grid;grid-template-columns:repeat(auto-fill,minmax(380px,1fr));gap:12px}"
    ".views figure{margin:0;border:1px solid #ddd;padding:4px}.views figcaption{font-size:.85em;color:#444}"
    ".crop{display:inline-block;position:relative;overflow:hidden;width:120px;height:120px;background:#eee;"
    "margin-right:2px}.crop img{position:absolute;max-width:none;border:0}"
    "details{font-size:.85em;color:#555}"
    "#g2p-3d .g2p-viewer{display:flex;gap:12px;align-items:stretch}#g2p-3d .g2p-viewer[hidden]{display:none}"
    ".g2p-canvas{flex:1;min-width:300px;height:520px;border:1px solid #ccc}"
    ".g2p-side{width:300px;font-size:.9em}.g2p-toggles label{display:block}"
    ".g2p-parts{list-style:none;padding:0;max-height:220px;overflow:auto;border-top:1px solid #ddd;"
    "border-bottom:1px solid #ddd}.g2p-parts li{padding:1px 2px}.g2p-parts li span:last-child{cursor:pointer}"
    ".g2p-parts li.sel{background:#e8eefc}.g2p-info table{margin:.3em 0}.g2p-info th{text-align:left}"
    ".g2p-fix{border:1px solid #bcd;background:#f4f8fd;padding:.3em .5em;margin:.4em 0}.g2p-fix label{display:block;"
    "margin:.15em 0}.g2p-fix input{width:6em}.g2p-fixes ol{padding-left:1.4em;margin:.3em "
    "0}.g2p-object-fix{display:block;margin:.3em 0}.g2p-object-fix input{width:11em}"
    ".g2p-fixes code{font-size:.85em;word-break:break-all}";

// Where the object lies in a view: a square around the pixels that show it
// (from the face-ID buffer), in pixels, so the page can show it large.
struct Crop {
  double x = 0, y = 0, side = 0;
};
Crop object_crop(const View& v) {
  const ImageI32& ids = v.face_id;
  int x0 = ids.width(), y0 = ids.height(), x1 = -1, y1 = -1;
  for (int y = 0; y < ids.height(); ++y)
    for (int x = 0; x < ids.width(); ++x)
      if (ids.at(x, y) >= 0) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  if (x1 < 0) return {0, 0, static_cast<double>(std::max(ids.width(), ids.height()))};
  const double side = std::max(x1 - x0 + 1, y1 - y0 + 1) * 1.12 + 6.0;
  return {(x0 + x1 + 1) / 2.0 - side / 2.0, (y0 + y1 + 1) / 2.0 - side / 2.0, side};
}

void cropped_image(std::ostringstream& h, const std::string& src, const Crop& c, int width, const std::string& alt) {
  const double tile = 120.0, scale = tile / c.side;
  h << "<a class=\"crop\" href=\"" << src << "\"><img src=\"" << src << "\" alt=\"" << escape(alt)
    << "\" style=\"width:" << number(width * scale, "%.1f") << "px;left:" << number(-c.x * scale, "%.1f")
    << "px;top:" << number(-c.y * scale, "%.1f") << "px\"></a>";
}

// Every view, shown where the object is: the render, the labels per pixel and
// the labels voted onto the faces, side by side.
void views_section(std::ostringstream& h, const PipelineResult& r) {
  h << "<h2>Views and labels</h2>\n<p class=\"note\">Each view: the render, the material of every pixel, and the "
       "final labels voted onto the faces. Click an image for the whole view.</p>\n";
  std::set<int> present;
  for (const Part& p : r.projection.parts) present.insert(p.label);
  h << "<div class=\"legend\">";
  for (int k = 0; k < r.table.size(); ++k)
    h << "<span" << (present.count(k) ? "" : " class=\"absent\"")
      << "><span class=\"sw\" style=\"background:" << detail::css_color(r.table[k].color) << "\"></span>"
      << escape(r.table[k].name) << "</span>";
  h << "</div>\n<div class=\"views\">\n";
  // The label images carry the legend on their right (write_label_maps).
  const int legend_width = label_legend(r.table).width();
  for (std::size_t i = 0; i < r.views.size(); ++i) {
    const View& v = r.views[i];
    const Crop c = object_crop(v);
    const std::string n = two_digits(i);
    const int width = v.face_id.width();
    h << "<figure>";
    cropped_image(h, "views/view_" + n + "_rgb.png", c, width, "view " + std::to_string(i));
    cropped_image(h, "segmented/view_" + n + "_labels.png", c, width + legend_width, "labels per pixel");
    cropped_image(h, "projected/view_" + n + "_labels.png", c, width + legend_width, "labels on the faces");
    h << "<figcaption>view " << i << ": render, per pixel, on the faces</figcaption></figure>\n";
  }
  h << "</div>\n";
}

// "a chair", "an oven".
std::string article(const std::string& noun) {
  const bool vowel = !noun.empty() && std::string("aeiou").find(noun.front()) != std::string::npos;
  return (vowel ? "an " : "a ") + noun;
}

// What the object was taken for, and what that kind usually weighs.
void object_line(std::ostringstream& h, const PipelineResult& r, double kind_confidence) {
  const Identification& id = r.identification;
  h << "<p id=\"g2p-object\">What it is: ";
  // The runners-up, as `g2p identify` lists them: "chair (40 %), bench (12 %)".
  auto others = [&](std::size_t from, std::size_t count) {
    std::string list;
    for (std::size_t i = from; i < id.candidates.size() && i < from + count; ++i)
      list += (list.empty() ? "" : ", ") + escape(id.candidates[i].kind) + " (" +
              number(100.0 * id.candidates[i].confidence, "%.0f") + " %)";
    return list;
  };
  if (!id.known()) {
    h << "<b>unknown</b>";
    if (!id.candidates.empty()) h << "; the likeliest kinds were " << others(0, 3);
    h << " (give it with <code>g2p run --object</code> to check its mass against its kind)</p>\n";
    return;
  }
  h << "<b>" << escape(id.kind()) << "</b> (from " << escape(id.source()) << ", "
    << number(100.0 * id.confidence(), "%.0f") << " % confident: " << escape(id.candidates.front().evidence) << ")";
  if (id.candidates.size() > 1) h << "; else perhaps " << others(1, 2);
  if (!r.kind.name.empty())
    h << "; " << escape(article(r.kind.name)) << " usually weighs " << number(r.kind.mass_kg[0]) << " to "
      << number(r.kind.mass_kg[1]) << " kg";
  else
    h << "; below the " << number(100.0 * kind_confidence, "%.0f")
      << " % the run needs to act on it, so nothing was assumed from it";
  if (r.size_assumed_m > 0) h << "; size assumed: longest side " << number(r.size_assumed_m) << " m";
  h << ". Correct it with <code>--object</code>.</p>\n";
}

// Everything a person should see before using the asset, at the top.
void warnings_banner(std::ostringstream& h, const PipelineResult& r) {
  std::vector<std::string> items = r.warnings;
  for (const StageReport& s : r.stages) {
    const std::string stage = to_string(s.stage);
    const bool told =
        std::any_of(items.begin(), items.end(), [&](const std::string& w) { return w.rfind(stage, 0) == 0; });
    if (!s.ok && !told)
      items.push_back(stage + " (" + s.backend + ") failed and the run went on without it: " + s.error);
  }
  const double mass = r.properties.object.mass_kg;
  if (!(std::isfinite(mass) && mass > 0))
    items.push_back("the total mass is " + number(mass) + " kg: no part has a usable mass");
  else if (mass < r.properties.mass_min_kg * 0.999 || mass > r.properties.mass_max_kg * 1.001)
    items.push_back("the total mass " + number(mass) + " kg lies outside its own plausible range (" +
                    number(r.properties.mass_min_kg) + " to " + number(r.properties.mass_max_kg) + " kg)");
  if (items.empty()) return;
  h << "<div class=\"banner\" id=\"g2p-warnings\"><h2>Check before use</h2><ul>\n";
  for (const std::string& w : items) h << "<li>" << escape(w) << "</li>\n";
  h << "</ul></div>\n";
}

void parts_table(std::ostringstream& h, const PipelineResult& r) {
  h << "<h2>Parts</h2>\n<table><tr><th>part</th><th>material</th><th>faces</th><th>area (m&sup2;)</th>"
       "<th>closed</th><th>volume (cm&sup3;)</th><th>density (kg/m&sup3;)</th><th>structure</th><th>mass (kg)</th>"
       "</tr>\n";
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) {
    const Part& p = r.projection.parts[i];
    h << "<tr><td>" << i << "</td><td class=\"l\">";
    if (r.table.valid_label(p.label))
      h << "<span class=\"sw\" style=\"background:" << detail::css_color(r.table[p.label].color) << "\"></span>"
        << escape(r.table[p.label].name);
    else
      h << "Unknown";
    h << "</td><td>" << p.faces.size() << "</td><td>" << number(p.area_m2) << "</td>";
    if (i < r.completion.parts.size() && i < r.properties.parts.size()) {
      const CompletedPart& c = r.completion.parts[i];
      const PartReport& pr = r.properties.parts[i];
      h << "<td>" << (c.ok ? "yes" : "<span class=\"warn\">no</span>") << "</td><td>"
        << number(c.checks.volume_m3 * 1e6) << "</td><td>" << number(pr.properties.density_kg_m3) << "</td><td>"
        << to_string(pr.properties.structure);
      if (pr.properties.structure == Structure::kHollow && pr.properties.wall_thickness_m > 0)
        h << ", " << number(pr.properties.wall_thickness_m * 1e3) << " mm walls";
      if (pr.contents.mass_kg > 0)
        h << ", " << number(pr.properties.contents_fill * 100.0) << " % full (" << number(pr.contents.mass_kg)
          << " kg at " << number(pr.properties.contents_density_kg_m3) << " kg/m&sup3;)";
      h << "</td><td>" << number(pr.mass.mass_kg) << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
}

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// What a stage did, in words a person who has not read the code follows.
std::string plain_words(const PipelineResult& r, const StageReport& s) {
  switch (s.stage) {
    case Stage::kLoad:
      return "Read " + plural(static_cast<std::size_t>(r.model.mesh.num_faces()), "triangle", "triangles") + " and " +
             plural(r.model.materials.size(), "material", "materials") + " from the file.";
    case Stage::kRender:
      return "Drew the object from " + plural(r.views.size(), "side", "sides") + " (the views above).";
    case Stage::kIdentify:
      if (!r.identification.known()) return "Could not tell what the object is; nothing was assumed from its kind.";
      return "Took the object for " + article(r.identification.kind()) + " (" + r.identification.source() + ")" +
             (r.size_assumed_m > 0 ? " and gave it that kind's typical size, since the file's looked normalised."
                                   : ".");
    case Stage::kSegment:
      return "Gave every pixel of every view one of " + std::to_string(r.table.size()) + " material classes.";
    case Stage::kProject: {
      std::size_t seen = 0;
      for (float t : r.projection.votes.total) seen += t > 0;
      return "Voted the pixels' classes onto the faces: " + std::to_string(seen) + " of " +
             std::to_string(r.model.mesh.num_faces()) +
             " faces were seen; the unseen ones took their neighbours' class. Same-class regions became " +
             plural(r.projection.parts.size(), "part", "parts") + ".";
    }
    case Stage::kRefine:
      if (r.refinement.labels.empty()) return "Kept the voted classes as they were.";
      return "Corrected the classes of " + plural(r.refinement.changes.size(), "face", "faces") +
             (r.refinement.fell_back ? " (it could not run: the voted classes stand)." : ".");
    case Stage::kComplete: {
      std::size_t closed = 0;
      for (const CompletedPart& c : r.completion.parts) closed += c.ok;
      return "Closed " + std::to_string(closed) + " of " + plural(r.completion.parts.size(), "part", "parts") +
             " into watertight volumes, so each has a volume and a mass.";
    }
    case Stage::kProperties:
      return "Gave each part a density and chose solid or hollow (hollow parts weigh their walls only); the object "
             "weighs " +
             number(r.properties.object.mass_kg) + " kg.";
    case Stage::kDecompose: {
      std::size_t hulls = 0;
      for (const AssetPart& p : r.asset.parts) hulls += p.collision.hulls.size();
      return "Split the parts into " + plural(hulls, "convex piece", "convex pieces") +
             " that a physics engine collides (the collision hulls in the 3D view).";
    }
    case Stage::kExport:
      return "Wrote the object as one rigid body with " + plural(r.asset.parts.size(), "part", "parts") + ".";
  }
  return "";
}

void stages_table(std::ostringstream& h, const PipelineResult& r) {
  h << "<h2>Stages</h2>\n<table><tr><th>stage</th><th class=\"l\">what it did</th><th class=\"l\">method</th><th>time "
       "(s)</th>"
       "<th>peak memory (MiB)</th></tr>\n";
  for (const StageReport& s : r.stages) {
    h << "<tr><td>" << to_string(s.stage) << "</td><td class=\"l\">";
    if (!s.ok) h << "<span class=\"warn\">It failed and the run went on without it: " << escape(s.error) << "</span> ";
    h << escape(plain_words(r, s));
    if (!s.notes.empty()) {
      h << "<details><summary>details</summary>";
      for (const std::string& n : s.notes) h << escape(n) << "<br>";
      h << "</details>";
    }
    h << "</td><td class=\"l\">" << escape(s.backend) << "</td><td>" << number(s.seconds, "%.2f") << "</td><td>"
      << number(static_cast<double>(s.peak_rss_bytes) / 1048576.0, "%.0f") << "</td></tr>\n";
  }
  h << "</table>\n";
}

}  // namespace

std::string summary_html(const PipelineResult& r, const PipelineOptions& o) {
  const MassProperties& m = r.properties.object;
  const detail::SummaryViewer viewer = detail::summary_viewer(r);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" << escape(r.asset.name)
    << " - libg2p</title>\n<style>" << kStyle << "</style></head><body>\n";
  h << "<h1>" << escape(r.asset.name) << "</h1>\n<p>" << escape(r.model.info.path) << ": " << r.model.mesh.num_faces()
    << " triangles, " << r.views.size() << " views, " << r.projection.parts.size() << " parts. Total mass <b>"
    << number(m.mass_kg) << " kg</b> (plausible range " << number(r.properties.mass_min_kg) << " to "
    << number(r.properties.mass_max_kg) << " kg"
    << (r.properties.mass_median_kg > 0
            ? "; judged by " + escape(r.properties.mass_judged_by) + ", median " + number(r.properties.mass_median_kg) +
                  " kg, 90 % interval " + number(r.properties.mass_p05_kg) + " to " + number(r.properties.mass_p95_kg) +
                  " kg"
            : std::string())
    << "), centre of mass (" << number(m.center_of_mass.x()) << ", " << number(m.center_of_mass.y()) << ", "
    << number(m.center_of_mass.z()) << ") m. Size " << number(r.properties.size.extent_m.x()) << " x "
    << number(r.properties.size.extent_m.y()) << " x " << number(r.properties.size.extent_m.z())
    << " m (height last; scale from " << escape(size_source(r.model.info)) << "). Run time "
    << number(r.seconds, "%.2f") << " s.</p>\n";
  object_line(h, r, o.kind_confidence);
  warnings_banner(h, r);
  if (!r.overrides_applied.empty()) {
    h << "<div class=\"corrections\" id=\"g2p-corrections\"><h2>Corrections applied</h2><ul>\n";
    for (const std::string& c : r.overrides_applied) h << "<li>" << escape(c) << "</li>\n";
    h << "</ul></div>\n";
  }
  h << viewer.section;
  parts_table(h, r);
  views_section(h, r);
  stages_table(h, r);
  h << "<h2>Files</h2>\n<ul>\n";
  for (const std::string& f : o.formats) {
    const std::string ext = f == "mjcf" ? ".xml" : "." + f;
    h << "<li><a href=\"" << escape(r.asset.name + ext) << "\">" << escape(r.asset.name + ext) << "</a></li>\n";
  }
  h << "<li><a href=\"report.json\">report.json</a> (per-part properties), <a href=\"run.json\">run.json</a>, "
       "<a href=\"faces.csv\">faces.csv</a>, <a href=\"labelled.ply\">labelled.ply</a></li>\n</ul>\n"
       "<p class=\"note\">Written by libg2p (Gen2Physics)."
    << (detail::summary_viewer_built() ? " The 3D view uses three.js (MIT licence), inlined in this page." : "")
    << "</p>\n"
    << viewer.scripts << "</body></html>\n";
  return h.str();
}

}  // namespace g2p
