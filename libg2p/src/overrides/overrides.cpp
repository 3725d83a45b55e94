// Overrides: the file format (parse, write), their resolution against a run's
// parts, and their application to labels (before complete) and to properties
// (an estimator that wraps another). docs/pipeline.md#overrides.
#include "g2p/overrides.h"
#include "core/physical_limits.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace g2p {

namespace {

using nlohmann::json;

constexpr double kMaxDensity = detail::kMaxDensity_kg_m3;

std::string entry_name(std::size_t i) { return "entry " + std::to_string(i + 1); }

std::string type_name(const json& v) { return v.type_name(); }

Status entry_error(const std::string& origin, std::size_t i, const std::string& what) {
  return Status::InvalidArgument(origin + ": overrides " + entry_name(i) + ": " + what);
}

bool positive_finite(const json& v) { return v.is_number() && std::isfinite(v.get<double>()) && v.get<double>() > 0; }

Result<Override> parse_entry(const json& e, std::size_t i, const MaterialTable& table, const std::string& origin) {
  if (!e.is_object()) return entry_error(origin, i, "is a " + type_name(e) + ", not an object");
  static const std::set<std::string> kKeys = {
      "part", "faces", "was", "class", "structure", "wall_thickness_m", "density_kg_m3", "contents", "note"};
  for (auto it = e.begin(); it != e.end(); ++it)
    if (!kKeys.count(it.key()))
      return entry_error(origin, i,
                         "unknown key '" + it.key() +
                             "' (part, faces, was, class, structure, wall_thickness_m, density_kg_m3, contents, note)");
  Override o;
  const bool has_part = e.contains("part"), has_faces = e.contains("faces");
  if (has_part == has_faces)
    return entry_error(origin, i,
                       has_part ? "gives both 'part' and 'faces'; give one"
                                : "selects nothing: give 'part' (a part index) or 'faces'");
  if (has_part) {
    const json& p = e["part"];
    if (!p.is_number_integer() || p.get<long long>() < 0 || p.get<long long>() > 1e9)
      return entry_error(origin, i, "'part' must be a part index (0, 1, ...), not " + p.dump());
    o.part = p.get<int>();
  } else {
    const json& f = e["faces"];
    if (!f.is_array() || f.empty())
      return entry_error(origin, i, "'faces' must be a non-empty list of face indices and [first, last] ranges");
    for (const json& item : f) {
      auto index = [](const json& v) {
        return v.is_number_integer() && v.get<long long>() >= 0 && v.get<long long>() < (1LL << 31);
      };
      if (index(item)) {
        o.faces.push_back({item.get<int>(), item.get<int>()});
      } else if (item.is_array() && item.size() == 2 && index(item[0]) && index(item[1]) &&
                 item[0].get<int>() <= item[1].get<int>()) {
        o.faces.push_back({item[0].get<int>(), item[1].get<int>()});
      } else {
        return entry_error(origin, i,
                           "'faces' holds " + item.dump() + ": give face indices (0, 1, ...) or [first, last] ranges");
      }
    }
    // Sorted and merged: each face once, however the ranges overlap.
    std::sort(o.faces.begin(), o.faces.end());
    std::vector<std::array<int, 2>> merged;
    for (const auto& r : o.faces) {
      if (!merged.empty() && static_cast<long long>(r[0]) <= static_cast<long long>(merged.back()[1]) + 1)
        merged.back()[1] = std::max(merged.back()[1], r[1]);
      else
        merged.push_back(r);
    }
    o.faces = std::move(merged);
  }
  if (e.contains("was")) {
    const json& w = e["was"];
    if (!has_part) return entry_error(origin, i, "'was' checks a 'part'; a 'faces' selection has nothing to check");
    if (!w.is_object())
      return entry_error(origin, i, "'was' must be an object like {\"class\": \"Wood\", \"faces\": 120}");
    for (auto it = w.begin(); it != w.end(); ++it) {
      if (it.key() == "class" && it.value().is_string()) {
        o.was_class = it.value().get<std::string>();
      } else if (it.key() == "faces" && it.value().is_number_integer() && it.value().get<long long>() >= 0 &&
                 it.value().get<long long>() < (1LL << 31)) {
        o.was_faces = it.value().get<int>();
      } else {
        return entry_error(origin, i,
                           "'was' holds '" + it.key() + "': " + it.value().dump() +
                               " (it takes \"class\", a name, and \"faces\", a count)");
      }
    }
  }
  if (e.contains("class")) {
    const json& c = e["class"];
    if (!c.is_string()) return entry_error(origin, i, "'class' must be a class name, not " + c.dump());
    o.class_name = c.get<std::string>();
    o.label = table.find(o.class_name);
    if (o.label == kUnknownLabel) {
      std::string names;
      for (int k = 0; k < table.size(); ++k) names += (k ? ", " : "") + table[k].name;
      return entry_error(origin, i, "unknown class '" + c.get<std::string>() + "' (the classes: " + names + ")");
    }
  }
  if (e.contains("structure")) {
    const json& s = e["structure"];
    const std::string v = s.is_string() ? s.get<std::string>() : std::string();
    if (v != "solid" && v != "hollow")
      return entry_error(origin, i, "'structure' must be \"solid\" or \"hollow\", not " + s.dump());
    o.set_structure = true;
    o.structure = v == "hollow" ? Structure::kHollow : Structure::kSolid;
  }
  if (e.contains("wall_thickness_m")) {
    const json& t = e["wall_thickness_m"];
    if (!positive_finite(t) || t.get<double>() > 10.0)
      return entry_error(origin, i, "'wall_thickness_m' must be a positive thickness in metres, not " + t.dump());
    if (o.set_structure && o.structure == Structure::kSolid)
      return entry_error(origin, i, "gives a wall thickness for a solid part; say \"structure\": \"hollow\"");
    o.wall_thickness_m = t.get<double>();
  }
  if (e.contains("density_kg_m3")) {
    const json& d = e["density_kg_m3"];
    if (!positive_finite(d) || d.get<double>() > kMaxDensity)
      return entry_error(origin, i,
                         "'density_kg_m3' must be a positive density up to 23000 kg/m^3 (osmium, the densest element, "
                         "is 22590), not " +
                             d.dump());
    o.density_kg_m3 = d.get<double>();
  }
  if (e.contains("contents")) {
    const json& c = e["contents"];
    const std::string form = "like {\"fill\": 0.8, \"density_kg_m3\": 1000}";
    if (!c.is_object()) return entry_error(origin, i, "'contents' must be an object " + form + ", not " + c.dump());
    if (!c.contains("fill"))
      return entry_error(origin, i, "'contents' needs \"fill\", the share of the cavity from 0 to 1 (80 % is 0.8)");
    for (auto it = c.begin(); it != c.end(); ++it)
      if (it.key() != "fill" && it.key() != "density_kg_m3")
        return entry_error(origin, i, "'contents' holds '" + it.key() + "' (it takes fill and density_kg_m3)");
    const json& f = c["fill"];
    if (!f.is_number() || !std::isfinite(f.get<double>()) || f.get<double>() < 0 || f.get<double>() > 1)
      return entry_error(origin, i,
                         "'contents' fill must be a share of the cavity from 0 to 1 (80 % is 0.8), not " + f.dump());
    o.set_contents = true;
    o.contents_fill = f.get<double>();
    if (c.contains("density_kg_m3")) {
      const json& d = c["density_kg_m3"];
      if (!positive_finite(d) || d.get<double>() > kMaxDensity)
        return entry_error(origin, i,
                           "'contents' density_kg_m3 must be a positive density up to 23000 kg/m^3 (osmium, the "
                           "densest element, is 22590), not " +
                               d.dump());
      o.contents_density_kg_m3 = d.get<double>();
    }
    if (o.set_structure && o.structure == Structure::kSolid && o.contents_fill > 0)
      return entry_error(origin, i, "fills a solid part; contents need \"structure\": \"hollow\"");
  }
  if (e.contains("note")) {
    if (!e["note"].is_string()) return entry_error(origin, i, "'note' must be text");
    o.note = e["note"].get<std::string>();
  }
  if (o.label == kUnknownLabel && !o.sets_properties())
    return entry_error(origin, i,
                       "changes nothing: give class, structure, wall_thickness_m, density_kg_m3 or contents");
  return o;
}

}  // namespace

Result<Overrides> parse_overrides(const std::string& text, const MaterialTable& table, const std::string& origin) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded())
    return Status::InvalidArgument(origin + ": not JSON (an overrides file is JSON, docs/pipeline.md#overrides)");
  if (!j.is_object() || !j.contains("format") || !j["format"].is_string() || j["format"] != "g2p-overrides")
    return Status::InvalidArgument(origin + ": not an overrides file (its \"format\" must be \"g2p-overrides\")");
  if (!j.contains("version") || !j["version"].is_number_integer())
    return Status::InvalidArgument(origin + ": the overrides file has no \"version\"");
  if (j["version"].get<long long>() != kOverridesVersion)
    return Status::InvalidArgument(origin + ": overrides version " + j["version"].dump() +
                                   ", but this g2p reads version " + std::to_string(kOverridesVersion));
  static const std::set<std::string> kKeys = {"format", "version", "model", "object", "faces_total", "overrides"};
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!kKeys.count(it.key()))
      return Status::InvalidArgument(origin + ": unknown key '" + it.key() +
                                     "' (format, version, model, object, faces_total, overrides)");
  Overrides out;
  if (j.contains("model")) {
    if (!j["model"].is_string()) return Status::InvalidArgument(origin + ": \"model\" must be a file name");
    out.model = j["model"].get<std::string>();
  }
  if (j.contains("object")) {
    if (!j["object"].is_string() || j["object"].get<std::string>().find_first_not_of(" \t") == std::string::npos)
      return Status::InvalidArgument(origin + ": \"object\" must be what the object is, in words (\"chair\")");
    out.object = j["object"].get<std::string>();
  }
  if (j.contains("faces_total")) {
    const json& n = j["faces_total"];
    if (!n.is_number_integer() || n.get<long long>() < 1 || n.get<long long>() > (1LL << 31) - 1)
      return Status::InvalidArgument(origin + ": \"faces_total\" must be the model's face count, not " + n.dump());
    out.faces_total = n.get<int>();
  }
  if (!j.contains("overrides") || !j["overrides"].is_array())
    return Status::InvalidArgument(origin + ": the overrides file has no \"overrides\" list");
  const json& entries = j["overrides"];
  for (std::size_t i = 0; i < entries.size(); ++i) {
    Result<Override> o = parse_entry(entries[i], i, table, origin);
    if (!o.ok()) return o.status();
    out.entries.push_back(std::move(*o));
  }
  return out;
}

Result<Overrides> read_overrides(const std::string& path, const MaterialTable& table) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the overrides file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_overrides(text.str(), table, path);
}

std::string overrides_json(const Overrides& overrides, const MaterialTable& table) {
  using ordered = nlohmann::ordered_json;
  std::string entries;
  for (const Override& o : overrides.entries) {
    ordered e = ordered::object();
    if (o.part >= 0) {
      e["part"] = o.part;
    } else {
      ordered faces = ordered::array();
      for (const auto& r : o.faces) faces.push_back(r[0] == r[1] ? ordered(r[0]) : ordered::array({r[0], r[1]}));
      e["faces"] = faces;
    }
    if (!o.was_class.empty() || o.was_faces >= 0) {
      ordered was = ordered::object();
      if (!o.was_class.empty()) was["class"] = o.was_class;
      if (o.was_faces >= 0) was["faces"] = o.was_faces;
      e["was"] = was;
    }
    if (table.valid_label(o.label))
      e["class"] = table[o.label].name;
    else if (!o.class_name.empty())
      e["class"] = o.class_name;
    if (o.set_structure) e["structure"] = to_string(o.structure);
    if (o.wall_thickness_m > 0) e["wall_thickness_m"] = o.wall_thickness_m;
    if (o.density_kg_m3 > 0) e["density_kg_m3"] = o.density_kg_m3;
    if (o.set_contents) e["contents"] = {{"fill", o.contents_fill}, {"density_kg_m3", o.contents_density_kg_m3}};
    if (!o.note.empty()) e["note"] = o.note;
    entries += (entries.empty() ? "\n    " : ",\n    ") + e.dump();  // one entry a line
  }
  std::string head = "{\n  \"format\": \"g2p-overrides\",\n  \"version\": " + std::to_string(kOverridesVersion) + ",\n";
  if (!overrides.model.empty()) head += "  \"model\": " + json(overrides.model).dump() + ",\n";
  if (!overrides.object.empty()) head += "  \"object\": " + json(overrides.object).dump() + ",\n";
  if (overrides.faces_total >= 0) head += "  \"faces_total\": " + std::to_string(overrides.faces_total) + ",\n";
  return head + "  \"overrides\": [" + entries + (entries.empty() ? "]" : "\n  ]") + "\n}\n";
}

Result<ResolvedOverrides> resolve_overrides(const Overrides& overrides, int num_faces, const std::vector<Part>& parts,
                                            const std::vector<int>& labels, const MaterialTable& table) {
  if (overrides.faces_total >= 0 && overrides.faces_total != num_faces)
    return Status::InvalidArgument("overrides: made for a model of " + std::to_string(overrides.faces_total) +
                                   " faces, applied to one of " + std::to_string(num_faces) +
                                   (overrides.model.empty() ? std::string() : " (they name " + overrides.model + ")"));
  if (labels.size() != static_cast<std::size_t>(num_faces))
    return Status::InvalidArgument("overrides: " + std::to_string(labels.size()) + " face labels for " +
                                   std::to_string(num_faces) + " faces");
  ResolvedOverrides r;
  r.overrides = overrides;
  r.class_entry.assign(static_cast<std::size_t>(num_faces), -1);
  r.structure_entry.assign(static_cast<std::size_t>(num_faces), -1);
  r.density_entry.assign(static_cast<std::size_t>(num_faces), -1);
  r.contents_entry.assign(static_cast<std::size_t>(num_faces), -1);
  // Classes by name in the run's table (the file may have been read with another).
  for (std::size_t i = 0; i < r.overrides.entries.size(); ++i) {
    Override& o = r.overrides.entries[i];
    if (o.class_name.empty() && o.label == kUnknownLabel) continue;
    const int label =
        o.class_name.empty() ? (table.valid_label(o.label) ? o.label : kUnknownLabel) : table.find(o.class_name);
    if (label == kUnknownLabel)
      return Status::InvalidArgument("overrides " + entry_name(i) + ": class '" + o.class_name +
                                     "' is not in the run's material table");
    o.label = label;
  }
  r.faces.assign(overrides.entries.size(), 0);
  for (std::size_t i = 0; i < overrides.entries.size(); ++i) {
    const Override& o = r.overrides.entries[i];
    const int entry = static_cast<int>(i);
    auto select = [&](int f) {
      const std::size_t face = static_cast<std::size_t>(f);
      if (o.label != kUnknownLabel) r.class_entry[face] = entry;
      if (o.sets_structure()) r.structure_entry[face] = entry;
      if (o.density_kg_m3 > 0) r.density_entry[face] = entry;
      if (o.set_contents) r.contents_entry[face] = entry;
    };
    if (o.part >= 0) {
      if (o.part >= static_cast<int>(parts.size()))
        return Status::InvalidArgument("overrides " + entry_name(i) + ": part " + std::to_string(o.part) +
                                       " does not exist (the run has " + std::to_string(parts.size()) +
                                       " parts, 0 to " + std::to_string(static_cast<int>(parts.size()) - 1) + ")");
      const Part& p = parts[static_cast<std::size_t>(o.part)];
      const std::string is_class = table.valid_label(p.label) ? table[p.label].name : "unknown";
      const bool class_differs = !o.was_class.empty() && table.find(o.was_class) != p.label;
      const bool faces_differ = o.was_faces >= 0 && o.was_faces != static_cast<int>(p.faces.size());
      if (class_differs || faces_differ)
        return Status::InvalidArgument(
            "overrides " + entry_name(i) + ": part " + std::to_string(o.part) + " is " + is_class + " with " +
            std::to_string(p.faces.size()) + " faces here, but the overrides were made for " +
            (o.was_class.empty() ? std::string("a part") : o.was_class) +
            (o.was_faces >= 0 ? " with " + std::to_string(o.was_faces) + " faces" : std::string()) +
            ": were they made for another model or run?");
      for (int f : p.faces) select(f);
      r.faces[i] = static_cast<int>(p.faces.size());
    } else {
      for (const auto& range : o.faces) {
        if (range[1] >= num_faces)
          return Status::InvalidArgument("overrides " + entry_name(i) + ": face " + std::to_string(range[1]) +
                                         " does not exist (the model has " + std::to_string(num_faces) +
                                         " faces, 0 to " + std::to_string(num_faces - 1) + ")");
        for (int f = range[0]; f <= range[1]; ++f) select(f);
        r.faces[i] += range[1] - range[0] + 1;  // ranges are merged: at most num_faces in all
      }
    }
  }
  return r;
}

Overrides as_face_selections(const ResolvedOverrides& resolved) {
  Overrides out;
  out.model = resolved.overrides.model;
  out.object = resolved.overrides.object;
  out.faces_total = static_cast<int>(resolved.class_entry.size());
  // Runs of consecutive faces whose winning entry is `e` in `winner`.
  auto ranges = [](const std::vector<int>& winner, int e) {
    std::vector<std::array<int, 2>> r;
    for (std::size_t f = 0; f < winner.size(); ++f) {
      if (winner[f] != e) continue;
      const int face = static_cast<int>(f);
      if (!r.empty() && r.back()[1] == face - 1)
        r.back()[1] = face;
      else
        r.push_back({face, face});
    }
    return r;
  };
  const std::vector<Override>& entries = resolved.overrides.entries;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Override& o = entries[i];
    if (o.label != kUnknownLabel) {
      Override c;
      c.faces = ranges(resolved.class_entry, static_cast<int>(i));
      c.label = o.label;
      c.class_name = o.class_name;
      c.note = o.note;
      if (!c.faces.empty()) out.entries.push_back(std::move(c));
    }
    if (o.sets_structure()) {
      Override s;
      s.faces = ranges(resolved.structure_entry, static_cast<int>(i));
      s.set_structure = o.set_structure;
      s.structure = o.structure;
      s.wall_thickness_m = o.wall_thickness_m;
      s.note = o.note;
      if (!s.faces.empty()) out.entries.push_back(std::move(s));
    }
    if (o.density_kg_m3 > 0) {
      Override d;
      d.faces = ranges(resolved.density_entry, static_cast<int>(i));
      d.density_kg_m3 = o.density_kg_m3;
      d.note = o.note;
      if (!d.faces.empty()) out.entries.push_back(std::move(d));
    }
    if (o.set_contents) {
      Override c;
      c.faces = ranges(resolved.contents_entry, static_cast<int>(i));
      c.set_contents = true;
      c.contents_fill = o.contents_fill;
      c.contents_density_kg_m3 = o.contents_density_kg_m3;
      c.note = o.note;
      if (!c.faces.empty()) out.entries.push_back(std::move(c));
    }
  }
  return out;
}

Result<std::vector<std::string>> apply_class_overrides(const ResolvedOverrides& resolved, const Mesh& mesh,
                                                       const FaceGraph& graph, std::vector<int>& labels,
                                                       std::vector<int>& face_part, std::vector<Part>& parts,
                                                       const MaterialTable& table) {
  const std::size_t n = static_cast<std::size_t>(mesh.num_faces());
  if (resolved.class_entry.size() != n || labels.size() != n || graph.num_faces() != mesh.num_faces())
    return Status::InvalidArgument("overrides: resolved for " + std::to_string(resolved.class_entry.size()) +
                                   " faces, applied to a mesh of " + std::to_string(n));
  const std::vector<Override>& entries = resolved.overrides.entries;
  std::vector<int> changed(entries.size(), 0);
  for (std::size_t f = 0; f < n; ++f) {
    const int e = resolved.class_entry[f];
    if (e < 0) continue;
    const int label = entries[static_cast<std::size_t>(e)].label;
    if (labels[f] != label) ++changed[static_cast<std::size_t>(e)];
    labels[f] = label;
  }
  // Connected same-class pieces, nothing merged: untouched parts stay as they were.
  PartitionOptions keep_all;
  keep_all.min_part_area_fraction = 0.0;
  parts = partition(mesh, graph, labels, face_part, keep_all, nullptr);
  std::vector<std::string> notes;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Override& o = entries[i];
    if (o.label == kUnknownLabel) continue;
    const std::string what =
        o.part >= 0 ? "part " + std::to_string(o.part) + (o.was_class.empty() ? "" : " (" + o.was_class + ")")
                    : std::to_string(resolved.faces[i]) + " faces";
    notes.push_back(entry_name(i) + ": " + what + (o.part >= 0 ? " is" : " are") + " now " + table[o.label].name +
                    " (" + std::to_string(changed[i]) + " faces changed class)" +
                    (o.note.empty() ? "" : ": " + o.note));
  }
  return notes;
}

Result<std::vector<std::string>> apply_class_overrides(const ResolvedOverrides& resolved, const Mesh& mesh,
                                                       Projection& projection, const MaterialTable& table) {
  Result<std::vector<std::string>> notes = apply_class_overrides(
      resolved, mesh, projection.graph, projection.labels.label, projection.face_part, projection.parts, table);
  if (!notes.ok()) return notes;
  // Confidences follow the new labels as apply_refinement's do: the votes' share.
  for (std::size_t f = 0; f < projection.labels.label.size() && f < projection.votes.total.size(); ++f) {
    const float* h = projection.votes.of(static_cast<int>(f));
    const int l = projection.labels.label[f];
    const float t = projection.votes.total[f];
    projection.labels.confidence[f] = h != nullptr && t > 0.f && l >= 0 ? h[l] / t : 0.f;
  }
  return notes;
}

namespace {

class OverridingEstimator final : public PropertyEstimator {
 public:
  OverridingEstimator(const PropertyEstimator& base, const ResolvedOverrides& resolved)
      : base_(base), resolved_(resolved) {}

  Result<PartProperties> estimate(const PropertyInput& input) const override {
    Result<PartProperties> r = base_.estimate(input);
    if (!r.ok() || input.part == nullptr) return r;
    // The entries that won any of the part's faces, per value, in file order.
    std::set<int> structure, density, contents;
    for (int f : input.part->faces) {
      const std::size_t i = static_cast<std::size_t>(f);
      if (i < resolved_.structure_entry.size() && resolved_.structure_entry[i] >= 0)
        structure.insert(resolved_.structure_entry[i]);
      if (i < resolved_.density_entry.size() && resolved_.density_entry[i] >= 0)
        density.insert(resolved_.density_entry[i]);
      if (i < resolved_.contents_entry.size() && resolved_.contents_entry[i] >= 0)
        contents.insert(resolved_.contents_entry[i]);
    }
    if (structure.empty() && density.empty() && contents.empty()) return r;
    PartProperties& p = *r;
    std::set<int> used;
    for (int e : structure) {
      const Override& o = resolved_.overrides.entries[static_cast<std::size_t>(e)];
      used.insert(e);
      if (o.wall_thickness_m <= 0 && o.structure == Structure::kSolid) {
        p.structure = Structure::kSolid;
        p.wall_thickness_m = 0.0;
        p.double_walled = false;
      } else {
        if (p.structure != Structure::kHollow) {  // the estimator's wall, else the class's
          p.double_walled = false;
          p.wall_thickness_m = input.table != nullptr && input.table->valid_label(p.label)
                                   ? (*input.table)[p.label].wall_thickness_m
                                   : p.wall_thickness_m;
          if (!(p.wall_thickness_m > 0)) p.wall_thickness_m = MaterialClass{}.wall_thickness_m;
        }
        p.structure = Structure::kHollow;
        if (o.wall_thickness_m > 0) {
          p.wall_thickness_m = o.wall_thickness_m;
          p.thickness_source = ValueSource::kUser;
        }
      }
      p.structure_source = ValueSource::kUser;
    }
    for (int e : density) {
      const Override& o = resolved_.overrides.entries[static_cast<std::size_t>(e)];
      used.insert(e);
      p.density_kg_m3 = p.density_min_kg_m3 = p.density_max_kg_m3 = o.density_kg_m3;
      p.density_source = ValueSource::kUser;
    }
    for (int e : contents) {
      const Override& o = resolved_.overrides.entries[static_cast<std::size_t>(e)];
      used.insert(e);
      p.contents_fill = o.contents_fill;
      p.contents_density_kg_m3 = o.contents_density_kg_m3;
    }
    // Walls the part cannot hold (a shell over its area would outweigh the
    // part as solid) are weighed as solid, and the correction says so.
    std::ostringstream too_thick;
    if (!structure.empty() && p.structure == Structure::kHollow && input.completed != nullptr &&
        input.completed->checks.area_m2 * p.wall_thickness_m >= input.completed->checks.volume_m3) {
      too_thick << " are more than the part holds (a shell over its " << input.completed->checks.area_m2
                << " m^2 would exceed its " << input.completed->checks.volume_m3 << " m^3), so it is weighed as solid";
      p.structure = Structure::kSolid;
      p.double_walled = false;
    }
    std::ostringstream what;
    what << "correction: ";
    const char* sep = "";
    if (!structure.empty()) {
      if (!too_thick.str().empty())
        what << "hollow, " << p.wall_thickness_m * 1000.0 << " mm walls" << too_thick.str();
      else if (p.structure == Structure::kSolid)
        what << "solid";
      else
        what << "hollow, " << p.wall_thickness_m * 1000.0 << " mm walls";
      sep = ", ";
    }
    if (!density.empty()) {
      what << sep << p.density_kg_m3 << " kg/m^3";
      sep = ", ";
    }
    if (!contents.empty()) {
      if (p.contents_fill > 0)
        what << sep << "contents " << p.contents_fill * 100.0 << " % full at " << p.contents_density_kg_m3 << " kg/m^3";
      else
        what << sep << "empty";
    }
    std::string notes;
    for (int e : used) {
      const std::string& n = resolved_.overrides.entries[static_cast<std::size_t>(e)].note;
      if (!n.empty() && notes.find(n) == std::string::npos) notes += (notes.empty() ? "" : "; ") + n;
    }
    p.notes.push_back(what.str() + (notes.empty() ? "" : " (" + notes + ")"));
    return r;
  }

 private:
  const PropertyEstimator& base_;
  const ResolvedOverrides& resolved_;
};

}  // namespace

std::unique_ptr<PropertyEstimator> make_overriding_estimator(const PropertyEstimator& base,
                                                             const ResolvedOverrides& resolved) {
  return std::make_unique<OverridingEstimator>(base, resolved);
}

}  // namespace g2p
