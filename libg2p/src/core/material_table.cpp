// MaterialTable: JSON reading, writing and validation.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/file_util.h"
#include "core/json_text.h"
#include "core/physical_limits.h"
#include "g2p/materials.h"

namespace g2p {

// The embedded default table (libg2p/data/materials.json, see embedded_data.cpp.in).
extern const char* const kDefaultMaterialTableJson;

namespace {

using nlohmann::json;

constexpr const char* kFormat = "g2p-material-table";
constexpr int kFormatVersion = 1;

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

Status check_class(const MaterialClass& c) {
  auto bad = [&](const std::string& what) { return Status::InvalidArgument("class '" + c.name + "': " + what); };
  if (c.name.empty()) return Status::InvalidArgument("a class has an empty name");
  const double values[] = {c.density_kg_m3,        c.density_min_kg_m3, c.density_max_kg_m3, c.friction_static,
                           c.friction_dynamic,     c.restitution,       c.wall_thickness_m,  c.max_solid_thickness_m,
                           c.max_wall_thickness_m, c.wall_range_m[0],   c.wall_range_m[1]};
  for (double v : values)
    if (!std::isfinite(v)) return bad("a value is not a finite number");
  if (c.density_kg_m3 <= 0.0) return bad("density_kg_m3 must be > 0, got " + fmt(c.density_kg_m3));
  if (!(c.density_min_kg_m3 > 0.0 && c.density_min_kg_m3 <= c.density_kg_m3 && c.density_kg_m3 <= c.density_max_kg_m3))
    return bad("density range [" + fmt(c.density_min_kg_m3) + ", " + fmt(c.density_max_kg_m3) +
               "] must be positive and contain density_kg_m3 " + fmt(c.density_kg_m3));
  if (c.density_max_kg_m3 > detail::kMaxDensity_kg_m3)
    return bad("density range up to " + fmt(c.density_max_kg_m3) + " kg/m^3: nothing is denser than " +
               fmt(detail::kMaxDensity_kg_m3) + " (osmium, the densest element, is 22590)");
  if (c.friction_static < 0.0 || c.friction_dynamic < 0.0) return bad("friction must be >= 0");
  if (c.restitution < 0.0 || c.restitution > 1.0)
    return bad("restitution must lie in [0, 1], got " + fmt(c.restitution));
  if (c.wall_thickness_m <= 0.0) return bad("wall_thickness_m must be > 0, got " + fmt(c.wall_thickness_m));
  if (c.max_solid_thickness_m < 0.0 ||
      (c.max_solid_thickness_m > 0.0 && c.max_solid_thickness_m < 2 * c.wall_thickness_m))
    return bad("max_solid_thickness_m must be 0 (no limit) or at least two walls (" + fmt(2 * c.wall_thickness_m) +
               "), got " + fmt(c.max_solid_thickness_m));
  if (c.max_wall_thickness_m < 0.0 || (c.max_wall_thickness_m > 0.0 && c.max_wall_thickness_m < c.wall_thickness_m))
    return bad("max_wall_thickness_m must be 0 (no limit) or at least wall_thickness_m (" + fmt(c.wall_thickness_m) +
               "), got " + fmt(c.max_wall_thickness_m));
  if (!(c.wall_range_m[0] == 0.0 && c.wall_range_m[1] == 0.0) &&
      !(c.wall_range_m[0] > 0.0 && c.wall_range_m[0] <= c.wall_range_m[1]))
    return bad("wall_range_m [" + fmt(c.wall_range_m[0]) + ", " + fmt(c.wall_range_m[1]) +
               "] must be positive and ordered (or absent)");
  if (c.max_wall_thickness_m > 0.0 && c.max_solid_thickness_m > 0.0 &&
      c.max_wall_thickness_m >= c.max_solid_thickness_m)
    return bad("max_wall_thickness_m (" + fmt(c.max_wall_thickness_m) + ") must be less than max_solid_thickness_m (" +
               fmt(c.max_solid_thickness_m) + "): a wall is no thicker than the thickest solid piece");
  return Status::Ok();
}

// Reads one class object; `where` is "origin: classes[i]".
// Keys a class object may have; anything else is a typo that would silently
// leave a default in place, so it is an error.
constexpr const char* kClassKeys[] = {
    "name",         "color",     "density_kg_m3",    "density_range_kg_m3",   "friction",
    "restitution",  "structure", "wall_thickness_m", "max_solid_thickness_m", "max_wall_thickness_m",
    "wall_range_m", "source"};

Result<MaterialClass> parse_class(const json& j, const std::string& where) {
  if (!j.is_object()) return Status::ParseError(where + ": expected an object");
  for (const auto& item : j.items()) {
    if (std::find(std::begin(kClassKeys), std::end(kClassKeys), item.key()) == std::end(kClassKeys)) {
      std::string known;
      for (const char* k : kClassKeys) known += std::string(known.empty() ? "" : ", ") + k;
      return Status::ParseError(where + ": unknown key '" + item.key() + "' (known: " + known + ")");
    }
  }
  MaterialClass c;
  auto number = [&](const json& obj, const char* key, double& out, bool required) -> Status {
    auto it = obj.find(key);
    if (it == obj.end()) {
      return required ? Status::ParseError(where + ": missing '" + key + "'") : Status::Ok();
    }
    if (!it->is_number()) return Status::ParseError(where + ": '" + key + "' must be a number");
    out = it->get<double>();
    return Status::Ok();
  };
  auto name = j.find("name");
  if (name == j.end() || !name->is_string()) return Status::ParseError(where + ": missing string 'name'");
  c.name = name->get<std::string>();
  const std::string here = where + " ('" + c.name + "')";

  G2P_RETURN_IF_ERROR(number(j, "density_kg_m3", c.density_kg_m3, true));
  c.density_min_kg_m3 = c.density_max_kg_m3 = c.density_kg_m3;
  if (auto r = j.find("density_range_kg_m3"); r != j.end()) {
    if (!r->is_array() || r->size() != 2 || !(*r)[0].is_number() || !(*r)[1].is_number())
      return Status::ParseError(here + ": 'density_range_kg_m3' must be [min, max]");
    c.density_min_kg_m3 = (*r)[0].get<double>();
    c.density_max_kg_m3 = (*r)[1].get<double>();
  }
  if (auto col = j.find("color"); col != j.end()) {
    if (!col->is_array() || col->size() != 3)
      return Status::ParseError(here + ": 'color' must be [r, g, b] with 0..255 integers");
    for (int k = 0; k < 3; ++k) {
      const json& v = (*col)[static_cast<std::size_t>(k)];
      if (!v.is_number_integer() || v.get<int>() < 0 || v.get<int>() > 255)
        return Status::ParseError(here + ": 'color' must be [r, g, b] with 0..255 integers");
      c.color[static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(v.get<int>());
    }
  }
  if (auto fr = j.find("friction"); fr != j.end()) {
    if (fr->is_number()) {
      c.friction_static = c.friction_dynamic = fr->get<double>();
    } else if (fr->is_object()) {
      G2P_RETURN_IF_ERROR(number(*fr, "static", c.friction_static, true));
      c.friction_dynamic = c.friction_static;
      G2P_RETURN_IF_ERROR(number(*fr, "dynamic", c.friction_dynamic, false));
    } else {
      return Status::ParseError(here + ": 'friction' must be a number or {\"static\", \"dynamic\"}");
    }
  }
  G2P_RETURN_IF_ERROR(number(j, "restitution", c.restitution, false));
  G2P_RETURN_IF_ERROR(number(j, "wall_thickness_m", c.wall_thickness_m, false));
  G2P_RETURN_IF_ERROR(number(j, "max_solid_thickness_m", c.max_solid_thickness_m, false));
  G2P_RETURN_IF_ERROR(number(j, "max_wall_thickness_m", c.max_wall_thickness_m, false));
  if (auto w = j.find("wall_range_m"); w != j.end()) {
    if (!w->is_array() || w->size() != 2 || !(*w)[0].is_number() || !(*w)[1].is_number())
      return Status::ParseError(here + ": 'wall_range_m' must be [thinnest, thickest] in metres");
    c.wall_range_m = {(*w)[0].get<double>(), (*w)[1].get<double>()};
  }
  if (auto s = j.find("structure"); s != j.end()) {
    const std::string v = s->is_string() ? s->get<std::string>() : "";
    if (iequals(v, "solid"))
      c.structure = Structure::kSolid;
    else if (iequals(v, "hollow"))
      c.structure = Structure::kHollow;
    else
      return Status::ParseError(here + ": 'structure' must be \"solid\" or \"hollow\"");
  }
  if (auto s = j.find("source"); s != j.end() && s->is_string()) c.source = s->get<std::string>();
  G2P_RETURN_IF_ERROR(check_class(c).with_context(where));
  return c;
}

}  // namespace

const char* to_string(Structure structure) { return structure == Structure::kHollow ? "hollow" : "solid"; }

Result<MaterialTable> MaterialTable::from_classes(std::vector<MaterialClass> classes, std::string name) {
  if (classes.empty()) return Status::InvalidArgument("material table '" + name + "' has no classes");
  for (std::size_t i = 0; i < classes.size(); ++i) {
    G2P_RETURN_IF_ERROR(check_class(classes[i]).with_context("classes[" + std::to_string(i) + "]"));
    for (std::size_t k = 0; k < i; ++k) {
      if (iequals(classes[k].name, classes[i].name))
        return Status::InvalidArgument("classes[" + std::to_string(i) + "]: name '" + classes[i].name +
                                       "' repeats classes[" + std::to_string(k) + "]");
    }
  }
  MaterialTable table;
  table.name_ = std::move(name);
  table.classes_ = std::move(classes);
  return table;
}

Result<MaterialTable> MaterialTable::from_json(const std::string& json_text, const std::string& origin) {
  json doc = json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return Status::ParseError(origin + ": not valid JSON");
  if (!doc.is_object()) return Status::ParseError(origin + ": expected a JSON object at the top level");
  if (auto f = doc.find("format"); f != doc.end() && (!f->is_string() || f->get<std::string>() != kFormat))
    return Status::ParseError(origin + ": 'format' must be \"" + std::string(kFormat) + "\"");
  if (auto v = doc.find("version"); v != doc.end() && !v->is_number_integer())
    return Status::ParseError(origin + ": 'version' must be an integer");
  if (auto v = doc.find("version"); v != doc.end() && v->get<int>() > kFormatVersion)
    return Status::Unsupported(origin + ": table version " + v->dump() + " is newer than this libg2p reads (" +
                               std::to_string(kFormatVersion) + ")");
  for (const auto& item : doc.items()) {
    static const char* const kTopKeys[] = {"format", "version", "name", "about", "classes"};
    if (std::find(std::begin(kTopKeys), std::end(kTopKeys), item.key()) == std::end(kTopKeys))
      return Status::ParseError(origin + ": unknown key '" + item.key() +
                                "' (known: format, version, name, about, classes)");
  }
  auto classes = doc.find("classes");
  if (classes == doc.end() || !classes->is_array()) return Status::ParseError(origin + ": missing array 'classes'");
  std::vector<MaterialClass> parsed;
  for (std::size_t i = 0; i < classes->size(); ++i) {
    Result<MaterialClass> c = parse_class((*classes)[i], origin + ": classes[" + std::to_string(i) + "]");
    if (!c.ok()) return c.status();
    parsed.push_back(std::move(*c));
  }
  std::string name = "custom";
  if (auto n = doc.find("name"); n != doc.end() && n->is_string()) name = n->get<std::string>();
  Result<MaterialTable> table = from_classes(std::move(parsed), name);
  if (!table.ok()) return table.status().with_context(origin);
  return table;
}

Result<MaterialTable> MaterialTable::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open material table");
  std::ostringstream text;
  text << in.rdbuf();
  return from_json(text.str(), path);
}

const MaterialTable& MaterialTable::paper_default() {
  static const MaterialTable table = [] {
    Result<MaterialTable> t = from_json(kDefaultMaterialTableJson, "embedded materials.json");
    if (!t.ok()) {
      // The embedded table is checked by the test suite: failing here is a
      // defect of the build, not of any input, and must not pass silently.
      std::fprintf(stderr, "libg2p: the built-in material table is broken: %s\n", t.status().to_string().c_str());
      std::abort();
    }
    return std::move(*t);
  }();
  return table;
}

std::string MaterialTable::to_json() const {
  json classes = json::array();
  for (const MaterialClass& c : classes_) {
    classes.push_back({{"name", c.name},
                       {"color", {c.color[0], c.color[1], c.color[2]}},
                       {"density_kg_m3", c.density_kg_m3},
                       {"density_range_kg_m3", {c.density_min_kg_m3, c.density_max_kg_m3}},
                       {"friction", {{"static", c.friction_static}, {"dynamic", c.friction_dynamic}}},
                       {"restitution", c.restitution},
                       {"structure", g2p::to_string(c.structure)},
                       {"wall_thickness_m", c.wall_thickness_m},
                       {"source", c.source}});
    // The limits only when set (0 = no limit, the default), so that tables
    // without them stay readable by a libg2p that predates the keys.
    if (c.max_solid_thickness_m > 0) classes.back()["max_solid_thickness_m"] = c.max_solid_thickness_m;
    if (c.max_wall_thickness_m > 0) classes.back()["max_wall_thickness_m"] = c.max_wall_thickness_m;
    if (c.wall_range_m[1] > 0) classes.back()["wall_range_m"] = {c.wall_range_m[0], c.wall_range_m[1]};
  }
  json doc = {{"format", kFormat}, {"version", kFormatVersion}, {"name", name_}, {"classes", classes}};
  return detail::json_text(doc, 2) + "\n";
}

Status MaterialTable::save(const std::string& path) const { return detail::write_file_atomically(path, to_json()); }

int MaterialTable::find(std::string_view name) const {
  for (std::size_t i = 0; i < classes_.size(); ++i)
    if (iequals(classes_[i].name, name)) return static_cast<int>(i);
  return kUnknownLabel;
}

}  // namespace g2p
