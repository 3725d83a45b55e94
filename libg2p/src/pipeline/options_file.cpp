// Options files (g2p/options_file.h): one writer, and one reader that lays a
// file's keys over a base and names the key path of anything it refuses.
#include "g2p/options_file.h"
#include "core/ascii.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/file_util.h"
#include "core/json_text.h"
#include "core/options_json.h"
#include "g2p/vlm.h"

namespace g2p {
namespace {

using nlohmann::json;

// A backend's settings as written: a URL's credentials and query values
// (`user:pw@`, `?key=`) as ***, since secrets are never written.
json backend_json(const BackendChoice& c) {
  json settings = json::object();
  for (const auto& [key, value] : c.settings)
    settings[key] = value.find("://") == std::string::npos ? value : redact_url(value);
  return {{"name", c.name}, {"settings", settings}};
}

const BackendChoice* backends(const PipelineOptions& o, std::size_t i, const char** name) {
  static const char* const kNames[] = {"renderer",  "identifier", "segmenter", "refiner",
                                       "completer", "estimator",  "decomposer"};
  const BackendChoice* const choices[] = {&o.renderer,  &o.identifier, &o.segmenter, &o.refiner,
                                          &o.completer, &o.estimator,  &o.decomposer};
  if (i >= std::size(choices)) return nullptr;
  *name = kNames[i];
  return choices[i];
}

json full_json(const RunOptions& r) {
  const PipelineOptions& o = r.pipeline;
  const ViewOptions& v = o.views;
  const DecomposeOptions& d = o.decompose;
  json j = {{"format", "g2p-options"},
            {"version", kOptionsFileVersion},
            {"import", detail::import_json(o.import)},
            {"anonymize_names", o.anonymize_names},
            {"base_color_only", o.base_color_only},
            {"renderer", backend_json(o.renderer)},
            {"views",
             {{"count", v.num_views},
              {"width", v.width},
              {"height", v.height},
              {"layout", to_string(v.layout)},
              {"fov_deg", v.fov_y_deg},
              {"orthographic", v.orthographic},
              {"margin", v.margin},
              {"elevation_deg", v.elevation_deg}}},
            {"identifier", backend_json(o.identifier)},
            {"object", o.object},
            {"kind_confidence", o.kind_confidence},
            {"size_from", to_string(o.size_policy)},
            {"kind_properties", o.kind_properties},
            {"kind_posterior", o.kind_posterior},
            {"kind_prior", o.kind_prior},
            {"segmenter", backend_json(o.segmenter)},
            {"project", detail::project_json(o.project)},
            {"refiner", backend_json(o.refiner)},
            {"completer", backend_json(o.completer)},
            {"completion_fallback", o.completion_fallback},
            {"keep_closed_parts", o.keep_closed_parts},
            {"resolve_thin_parts", o.resolve_thin_parts},
            {"estimator", backend_json(o.estimator)},
            {"decomposer", backend_json(o.decomposer)},
            {"decompose",
             {{"max_hulls", d.max_hulls},
              {"max_vertices_per_hull", d.max_vertices_per_hull},
              {"min_depth_m", d.min_depth_m},
              {"measure_resolution", d.measure_resolution},
              {"coverage_tolerance", d.coverage_tolerance},
              {"max_hulls_per_object", d.max_hulls_per_object}}},
            {"name", o.name},
            {"formats", o.formats},
            {"free_joint", o.export_options.free_joint},
            {"use_static_friction", o.export_options.use_static_friction},
            {"scale_contacts", o.export_options.scale_contacts},
            {"contact_sink", o.export_options.contact_sink},
            {"timestep_s", o.export_options.timestep_s},
            {"memory_limit_gib", static_cast<double>(o.memory_limit_bytes) / (1024.0 * 1024.0 * 1024.0)}};
  return j;
}

// Lays `patch` over `base` (both objects): every key of `patch` must be one
// of `base`'s, with a value of the same JSON type. A backend's "settings" are
// replaced whole, and a new backend "name" without "settings" drops the
// base's (they belong to the other backend).
Status overlay(json& base, const json& patch, const std::string& path) {
  if (!patch.is_object()) return Status::ParseError((path.empty() ? "the file" : path) + ": expected an object");
  const bool backend = base.contains("settings") && base.contains("name");
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    const std::string key = path.empty() ? it.key() : path + "." + it.key();
    if (!base.contains(it.key())) {
      std::string known;
      for (auto b = base.begin(); b != base.end(); ++b) known += (known.empty() ? "" : ", ") + b.key();
      return Status::ParseError(key + ": unknown key (known here: " + known + ")");
    }
    json& target = base[it.key()];
    const json& value = it.value();
    if (backend && it.key() == "settings") {
      if (!value.is_object()) return Status::ParseError(key + ": expected an object of KEY: \"VALUE\"");
      for (auto s = value.begin(); s != value.end(); ++s)
        if (!s.value().is_string() && !s.value().is_number() && !s.value().is_boolean())
          return Status::ParseError(key + "." + s.key() + ": expected a value as on the command line (\"0.5\")");
      target = json::object();
      for (auto s = value.begin(); s != value.end(); ++s)
        target[s.key()] = s.value().is_string() ? s.value().get<std::string>() : s.value().dump();
      continue;
    }
    if (backend && it.key() == "name" && value.is_string() && value != target && !patch.contains("settings"))
      base["settings"] = json::object();
    if (target.is_object()) {
      G2P_RETURN_IF_ERROR(overlay(target, value, key));
      continue;
    }
    const bool same_type = (target.is_number() && value.is_number()) || target.type() == value.type();
    if (!same_type) {
      const char* want = target.is_number_integer() ? "an integer"
                         : target.is_number()       ? "a number"
                         : target.is_boolean()      ? "true or false"
                         : target.is_string()       ? "a string"
                                                    : "a list of strings";
      return Status::ParseError(key + ": expected " + std::string(want) + ", got " + value.dump());
    }
    if (target.is_number_integer() && !value.is_number_integer())
      return Status::ParseError(key + ": expected an integer, got " + value.dump());
    if (target.is_array() && !std::all_of(value.begin(), value.end(), [](const json& e) { return e.is_string(); }))
      return Status::ParseError(key + ": expected a list of strings, got " + value.dump());
    target = value;
  }
  return Status::Ok();
}

BackendChoice backend_of(const json& j) {
  return BackendChoice{j.at("name").get<std::string>(), j.at("settings").get<BackendSettings>()};
}

// The merged document as options; names the key of a word that names nothing.
Result<RunOptions> options_of(const json& j, RunOptions r) {
  PipelineOptions& o = r.pipeline;
  const json& i = j.at("import");
  G2P_RETURN_IF_ERROR(detail::read_import_json(i, o.import));
  if (!(o.import.unit_scale >= 0.0) || !(o.import.height_m >= 0.0) || !(o.import.longest_side_m >= 0.0))
    return Status::InvalidArgument("import: unit_scale, height_m and longest_side_m must be 0 (unset) or more");
  if (o.import.height_m > 0.0 && o.import.longest_side_m > 0.0)
    return Status::InvalidArgument("import: give height_m or longest_side_m, not both");
  o.anonymize_names = j.at("anonymize_names").get<bool>();
  o.base_color_only = j.at("base_color_only").get<bool>();
  o.renderer = backend_of(j.at("renderer"));
  const json& v = j.at("views");
  o.views.num_views = v.at("count").get<int>();
  o.views.width = v.at("width").get<int>();
  o.views.height = v.at("height").get<int>();
  Result<ViewLayout> layout = parse_view_layout(v.at("layout").get<std::string>());
  if (!layout.ok()) return layout.status().with_context("views.layout");
  o.views.layout = *layout;
  o.views.fov_y_deg = v.at("fov_deg").get<double>();
  o.views.orthographic = v.at("orthographic").get<bool>();
  o.views.margin = v.at("margin").get<double>();
  o.views.elevation_deg = v.at("elevation_deg").get<double>();
  o.identifier = backend_of(j.at("identifier"));
  o.object = j.at("object").get<std::string>();
  o.kind_confidence = j.at("kind_confidence").get<double>();
  Result<SizePolicy> size = parse_size_policy(j.at("size_from").get<std::string>());
  if (!size.ok()) return size.status().with_context("size_from");
  o.size_policy = *size;
  o.kind_properties = j.at("kind_properties").get<bool>();
  // Absent from files written before #65: the default.
  if (j.contains("kind_posterior")) o.kind_posterior = j.at("kind_posterior").get<bool>();
  o.kind_prior = j.at("kind_prior").get<double>();
  o.segmenter = backend_of(j.at("segmenter"));
  G2P_RETURN_IF_ERROR(detail::read_project_json(j.at("project"), o.project));
  o.refiner = backend_of(j.at("refiner"));
  o.completer = backend_of(j.at("completer"));
  o.completion_fallback = j.at("completion_fallback").get<std::string>();
  o.keep_closed_parts = j.at("keep_closed_parts").get<bool>();
  o.resolve_thin_parts = j.at("resolve_thin_parts").get<bool>();
  o.estimator = backend_of(j.at("estimator"));
  o.decomposer = backend_of(j.at("decomposer"));
  const json& d = j.at("decompose");
  o.decompose.max_hulls = d.at("max_hulls").get<int>();
  o.decompose.max_vertices_per_hull = d.at("max_vertices_per_hull").get<int>();
  o.decompose.min_depth_m = d.at("min_depth_m").get<double>();
  o.decompose.measure_resolution = d.at("measure_resolution").get<int>();
  o.decompose.coverage_tolerance = d.at("coverage_tolerance").get<double>();
  o.decompose.max_hulls_per_object = d.at("max_hulls_per_object").get<int>();
  o.name = j.at("name").get<std::string>();
  o.formats = j.at("formats").get<std::vector<std::string>>();
  o.export_options.free_joint = j.at("free_joint").get<bool>();
  o.export_options.use_static_friction = j.at("use_static_friction").get<bool>();
  o.export_options.scale_contacts = j.at("scale_contacts").get<bool>();
  o.export_options.contact_sink = j.at("contact_sink").get<double>();
  o.export_options.timestep_s = j.at("timestep_s").get<double>();
  if (!(o.export_options.contact_sink > 0.0 && o.export_options.contact_sink <= 0.5))
    return Status::InvalidArgument("contact_sink: must lie in (0, 0.5] (a share of the object's smallest side)");
  if (!(o.export_options.timestep_s >= 0.0 && o.export_options.timestep_s <= 0.1))
    return Status::InvalidArgument("timestep_s: must lie in [0, 0.1] s (0: from the contacts)");
  const double gib = j.at("memory_limit_gib").get<double>();
  if (!(gib >= 0.0) || gib > 1e6) return Status::InvalidArgument("memory_limit_gib: must be 0 (none) or more GiB");
  o.memory_limit_bytes = static_cast<std::size_t>(gib * 1024.0 * 1024.0 * 1024.0);
  return r;
}

}  // namespace

std::string options_file_json(const RunOptions& options) {
  json j = full_json(options);
  if (options.materials.to_json() != MaterialTable::paper_default().to_json())
    j["materials"] = json::parse(options.materials.to_json());
  return detail::json_text(j, 2) + "\n";
}

Result<RunOptions> parse_options_file(const std::string& text, const std::string& where, const RunOptions& base) {
  json patch = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (patch.is_discarded()) return Status::ParseError(where + ": not JSON");
  if (!patch.is_object()) return Status::ParseError(where + ": expected a JSON object of options");
  if (patch.contains("format") && patch["format"] != "g2p-options")
    return Status::ParseError(where + ": format " + patch["format"].dump() + " is not \"g2p-options\"");
  if (patch.contains("version") && patch["version"] != kOptionsFileVersion)
    return Status::InvalidArgument(where + ": options file version " + patch["version"].dump() +
                                   ", and this libg2p reads version " + std::to_string(kOptionsFileVersion));
  RunOptions r = base;
  if (patch.contains("materials")) {
    if (!patch["materials"].is_object())
      return Status::ParseError(where + ": materials: expected a material table (docs/materials.md)");
    Result<MaterialTable> table = MaterialTable::from_json(patch["materials"].dump(), where + ": materials");
    if (!table.ok()) return table.status();
    r.materials = std::move(*table);
    patch.erase("materials");
  }
  json merged = full_json(base);
  if (Status s = overlay(merged, patch, ""); !s.ok()) return s.with_context(where);
  try {
    Result<RunOptions> out = options_of(merged, std::move(r));
    if (!out.ok()) return out.status().with_context(where);
    return out;
  } catch (const json::exception& e) {  // a type overlay() let through (an integer's range)
    return Status::ParseError(where + ": " + e.what());
  }
}

Result<RunOptions> read_options_file(const std::string& path, const RunOptions& base) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(path + ": cannot open the options file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_options_file(text.str(), path, base);
}

Status write_options_file(const std::string& path, const RunOptions& options) {
  return detail::write_file_atomically(path, options_file_json(options));
}

std::vector<std::string> options_file_redactions(const RunOptions& options) {
  std::vector<std::string> keys;
  const char* name = nullptr;
  for (std::size_t i = 0; const BackendChoice* c = backends(options.pipeline, i, &name); ++i)
    for (const auto& [key, value] : c->settings)
      if (value.find("://") != std::string::npos && redact_url(value) != value)
        keys.push_back(std::string(name) + ".settings." + key);
  return keys;
}

const char* to_string(UpAxis up) {
  switch (up) {
    case UpAxis::kX: return "x";
    case UpAxis::kY: return "y";
    case UpAxis::kZ: return "z";
    default: return "auto";
  }
}

Result<UpAxis> parse_up_axis(const std::string& text) {
  for (UpAxis a : {UpAxis::kAuto, UpAxis::kX, UpAxis::kY, UpAxis::kZ})
    if (detail::lower_case(text) == to_string(a)) return a;
  return Status::InvalidArgument("unknown up axis '" + text + "' (auto, x, y, z)");
}

const char* to_string(ViewLayout layout) {
  switch (layout) {
    case ViewLayout::kFibonacci: return "fibonacci";
    case ViewLayout::kTurntable: return "turntable";
    default: return "sphere";
  }
}

Result<ViewLayout> parse_view_layout(const std::string& text) {
  for (ViewLayout l : {ViewLayout::kSphere, ViewLayout::kFibonacci, ViewLayout::kTurntable})
    if (detail::lower_case(text) == to_string(l)) return l;
  return Status::InvalidArgument("unknown view layout '" + text + "' (sphere, fibonacci, turntable)");
}

const char* to_string(VoteMode mode) { return mode == VoteMode::kSoft ? "soft" : "hard"; }

Result<VoteMode> parse_vote_mode(const std::string& text) {
  if (detail::lower_case(text) == "hard") return VoteMode::kHard;
  if (detail::lower_case(text) == "soft") return VoteMode::kSoft;
  return Status::InvalidArgument("unknown vote '" + text + "' (hard, soft)");
}

}  // namespace g2p
