// The Completer base class, the registry, the fallback driver and the files
// the stage writes.
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include <tbb/parallel_for.h>

#include "complete/backends.h"
#include "complete/closed_parts.h"
#include "core/file_util.h"
#include "core/json_text.h"
#include "g2p/io.h"

namespace g2p {

Completer::~Completer() = default;

SettingsSpec Completer::settings() { return SettingsSpec("this completer"); }

Status Completer::configure(const BackendSettings& settings) { return this->settings().apply(settings); }

Registry<Completer>& completer_registry() {
  static Registry<Completer>* registry = [] {
    auto* r = new Registry<Completer>("completer");  // never destroyed: usable during static destruction
    (void)r->add("partition", &make_partition_completer);
    (void)r->add("external", &make_external_completer);
    return r;
  }();
  return *registry;
}

namespace {

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * fraction);
  return text;
}

std::string cm3(double m3) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g cm^3", m3 * 1e6);
  return text;
}

// Runs the completer and, for the parts it failed, the fallback.
Result<Completion> complete_with_fallback(const CompletionInput& input, const Completer& completer,
                                          const Completer* fallback) {
  const std::size_t np = input.parts->size();
  Result<Completion> first = completer.complete(input);
  if (!first.ok() && first.status().code() == StatusCode::kCancelled) return first.status();
  Completion out;
  if (first.ok()) {
    out = std::move(*first);
    if (out.parts.size() != np)
      return Status::Internal("complete: the completer returned " + std::to_string(out.parts.size()) + " parts for " +
                              std::to_string(np));
  } else {
    if (fallback == nullptr) return first.status();
    out.notes.push_back("the completer failed (" + first.status().message() + "); every part uses the fallback");
    out.parts.resize(np);
    for (std::size_t p = 0; p < np; ++p) {
      out.parts[p].part = static_cast<int>(p);
      out.parts[p].label = (*input.parts)[p].label;
    }
  }
  bool any_failed = false;
  for (std::size_t p = 0; p < np; ++p) any_failed |= !out.parts[p].ok && !input.is_kept(p);
  if (any_failed && fallback != nullptr) {
    Result<Completion> second = fallback->complete(input);
    if (!second.ok() && second.status().code() == StatusCode::kCancelled) return second.status();
    if (!second.ok()) {
      out.notes.push_back("the fallback failed too: " + second.status().message());
    } else {
      if (out.object_volume_m3 == 0.0) out.object_volume_m3 = second->object_volume_m3;
      if (out.grid_spacing_m == 0.0) out.grid_spacing_m = second->grid_spacing_m;
      for (std::size_t p = 0; p < np && p < second->parts.size(); ++p) {
        CompletedPart& mine = out.parts[p];
        if (mine.ok || input.is_kept(p)) continue;
        CompletedPart& theirs = second->parts[p];
        std::vector<std::string> notes = std::move(mine.notes);
        notes.push_back("fell back to '" + theirs.backend + "'");
        for (auto& n : theirs.notes) notes.push_back(std::move(n));
        mine = std::move(theirs);
        mine.notes = std::move(notes);
      }
      for (auto& n : second->notes) out.notes.push_back("fallback: " + n);
    }
  }
  return out;
}

// How far a completion's volumes lie from the input's (estimate_volumes):
// per part where the estimate judges it alone, and for the parts together.
struct VolumeJudgement {
  std::vector<double> part;  // (ours - input) / input; NaN where not judged
  double object = std::numeric_limits<double>::quiet_NaN();
  double object_sum_m3 = 0.0;
  std::vector<char> failing;  // beyond the tolerance, alone or with the object
  int num_failing = 0;
  // Summed relative errors, judged parts and the object: the lower, the
  // closer the completion is to the input.
  double score = 0.0;
};

VolumeJudgement judge_volumes(const VolumeEstimate& estimate, const CompletionOptions& options, const Completion& c) {
  VolumeJudgement j;
  const std::size_t np = c.parts.size();
  j.part.assign(np, std::numeric_limits<double>::quiet_NaN());
  j.failing.assign(np, 0);
  for (std::size_t p = 0; p < np && p < estimate.part_m3.size(); ++p) {
    const CompletedPart& part = c.parts[p];
    // Enough rays through the part for a sampled estimate (sampling error
    // well under the tolerance), and a volume bounded by its own faces.
    if (estimate.part_intervals[p] < 100 || estimate.part_own_fraction[p] < options.volume_check_own_fraction ||
        !(estimate.part_m3[p] > 0) || part.mesh.num_faces() == 0)
      continue;
    j.part[p] = (part.checks.volume_m3 - estimate.part_m3[p]) / estimate.part_m3[p];
    j.score += std::abs(j.part[p]);
    if (std::abs(j.part[p]) > options.volume_tolerance) j.failing[p] = 1;
  }
  for (const CompletedPart& part : c.parts) j.object_sum_m3 += part.checks.volume_m3;
  if (estimate.object_m3 > 0) {
    j.object = (j.object_sum_m3 - estimate.object_m3) / estimate.object_m3;
    j.score += std::abs(j.object);
    // The parts the estimate could not judge alone fail with the object.
    if (std::abs(j.object) > options.volume_tolerance)
      for (std::size_t p = 0; p < np; ++p)
        if (c.parts[p].backend != "input" && !std::isfinite(j.part[p]) && c.parts[p].mesh.num_faces() > 0)
          j.failing[p] = 1;
  }
  for (char f : j.failing) j.num_failing += f;
  return j;
}

// Holds every part to the input's own volume: fields, notes, ok = false.
void apply_judgement(const VolumeEstimate& estimate, const CompletionOptions& options, const VolumeJudgement& j,
                     Completion& out) {
  out.input_volume_m3 = estimate.object_m3;
  for (std::size_t p = 0; p < out.parts.size() && p < estimate.part_m3.size(); ++p) {
    CompletedPart& part = out.parts[p];
    part.input_volume_m3 = estimate.part_m3[p];
    part.volume_difference = j.part[p];
    if (!std::isfinite(j.part[p]) || std::abs(j.part[p]) <= options.volume_tolerance) continue;
    part.ok = false;
    part.notes.push_back("volume check: the closed part holds " + cm3(part.checks.volume_m3) + ", its input faces " +
                         cm3(estimate.part_m3[p]) + " (" + (j.part[p] > 0 ? "+" : "") + percent(j.part[p]) +
                         ", more than the " + percent(options.volume_tolerance) + " allowed)");
  }
  // The whole object catches what no part alone could be judged on (a thin
  // board whose two faces became two parts, each half of every interval).
  if (!std::isfinite(j.object) || std::abs(j.object) <= options.volume_tolerance) return;
  const std::string what = std::string("the parts together hold ") + cm3(j.object_sum_m3) +
                           ", the input's faces enclose " + cm3(estimate.object_m3) + " (" + (j.object > 0 ? "+" : "") +
                           percent(j.object) + ", more than the " + percent(options.volume_tolerance) + " allowed)";
  out.notes.push_back("volume check: " + what);
  for (std::size_t p = 0; p < out.parts.size(); ++p) {
    CompletedPart& part = out.parts[p];
    if (!j.failing[p] || std::isfinite(j.part[p])) continue;
    part.ok = false;
    part.notes.push_back("volume check: not judged alone, and " + what);
  }
}

// The thinnest of the failing parts, metres: twice its estimated volume over
// its area (a slab's thickness); 0 where none can say.
double thinnest_failing(const VolumeEstimate& estimate, const std::vector<Part>& parts, const VolumeJudgement& j) {
  double thinnest = 0.0;
  for (std::size_t p = 0; p < parts.size() && p < estimate.part_m3.size(); ++p) {
    if (!j.failing[p] || estimate.part_intervals[p] < 100 || !(estimate.part_m3[p] > 0) || !(parts[p].area_m2 > 0))
      continue;
    const double t = 2.0 * estimate.part_m3[p] / parts[p].area_m2;
    if (thinnest == 0.0 || t < thinnest) thinnest = t;
  }
  return thinnest;
}

// The parts whose faces already bound a solid (closed_part_surface), found
// in parallel, with their checks: the kept meshes (empty for the others) and
// the CompletedPart each becomes.
struct KeptParts {
  std::vector<Mesh> meshes;
  std::vector<CompletedPart> parts;
  std::size_t count = 0;
};

KeptParts find_kept_parts(const CompletionInput& input, const CompletionOptions& options) {
  const std::size_t np = input.parts->size();
  KeptParts kept;
  kept.meshes.resize(np);
  kept.parts.resize(np);
  if (!options.keep_closed_parts) return kept;
  const double weld = detail::weld_distance(*input.mesh, options.weld_tolerance);  // once, not per part
  tbb::parallel_for(std::size_t{0}, np, [&](std::size_t p) {
    MeshChecks checks;  // closed_part_surface's, self-intersections included
    Mesh closed = detail::closed_part_surface_checked(*input.mesh, (*input.parts)[p], weld, checks);
    if (closed.num_faces() == 0) return;
    CompletedPart& part = kept.parts[p];
    part.part = static_cast<int>(p);
    part.label = (*input.parts)[p].label;
    part.backend = "input";
    // Its surface is its patch's own faces: nothing lies away from them.
    part.checks = checks;
    part.checks.max_distance_m = 0.0;
    part.checks.relative_distance = 0.0;
    part.ok = part.checks.watertight();
    part.notes.push_back("kept as given: its faces already bound a solid");
    part.mesh = closed;
    kept.meshes[p] = std::move(closed);
  });
  for (const Mesh& m : kept.meshes) kept.count += m.num_faces() > 0;
  return kept;
}

// The completer's result with the kept parts in place.
Result<Completion> run_completer(const CompletionInput& input, const Completer& completer, const Completer* fallback,
                                 const KeptParts& kept) {
  const std::size_t np = input.parts->size();
  const std::size_t num_kept = kept.count;
  Completion out;
  if (num_kept < np || np == 0) {
    CompletionInput with_kept = input;
    with_kept.kept = &kept.meshes;
    Result<Completion> done = complete_with_fallback(with_kept, completer, fallback);
    if (!done.ok()) return done.status();
    out = std::move(*done);
  } else {
    out.parts.resize(np);
    out.notes.push_back("every part's faces already bound a solid: nothing to complete");
  }
  for (std::size_t p = 0; p < np; ++p)
    if (kept.meshes[p].num_faces() > 0) out.parts[p] = kept.parts[p];
  out.kept_parts = static_cast<int>(num_kept);
  if (num_kept > 0 && num_kept < np)
    out.notes.push_back(std::to_string(num_kept) + " of " + std::to_string(np) +
                        " parts kept as given (their faces already bound a solid)");
  return out;
}

// The failing parts that close as shells of their measured thickness
// (thin_part_shell), all at once: true if the completion now agrees better
// with the input and `out` holds it.
bool try_thin_shells(const CompletionInput& input, const VolumeEstimate& estimate, const CompletionOptions& options,
                     VolumeJudgement& judged, Completion& out) {
  Completion trial = out;
  std::vector<int> shelled;
  for (std::size_t p = 0; p < trial.parts.size(); ++p) {
    if (!judged.failing[p] || trial.parts[p].backend == "input") continue;
    Mesh shell = thin_part_shell(*input.mesh, *input.parts, p, options.weld_tolerance);
    if (shell.num_faces() == 0) continue;
    CompletedPart& part = trial.parts[p];
    const Mesh patch = part_patch(*input.mesh, (*input.parts)[p]);
    part.mesh = std::move(shell);
    part.checks = check_closed_mesh(part.mesh, &patch);
    part.backend = "shell";
    part.ok = part.checks.watertight();
    part.notes.push_back("closed as a shell of its measured thickness: the completer's surface held " +
                         cm3(out.parts[p].checks.volume_m3) + ", its input faces " + cm3(estimate.part_m3[p]));
    shelled.push_back(static_cast<int>(p));
  }
  if (shelled.empty()) return false;
  VolumeJudgement again = judge_volumes(estimate, options, trial);
  if (!(again.score < judged.score) || again.num_failing > judged.num_failing) return false;
  trial.notes.push_back(std::to_string(shelled.size()) +
                        " part(s) too thin for the completer closed as shells of their measured thickness");
  out = std::move(trial);
  judged = std::move(again);
  return true;
}

}  // namespace

Result<Completion> complete(const CompletionInput& input, const Completer& completer, const Completer* fallback,
                            const CompletionOptions& options) {
  if (input.parts == nullptr) return Status::InvalidArgument("complete: no parts");
  if (input.mesh == nullptr) return Status::InvalidArgument("complete: no mesh");
  const std::size_t np = input.parts->size();
  const KeptParts kept = find_kept_parts(input, options);  // parts already closed are kept as they are
  Result<Completion> first = run_completer(input, completer, fallback, kept);
  if (!first.ok()) return first.status();
  Completion out = std::move(*first);

  // The independent volume check (estimate_volumes), and where it fails, the
  // second tries of resolve_thin_parts.
  if (options.volume_tolerance > 0) {
    const VolumeEstimate estimate = estimate_volumes(*input.mesh, *input.parts, options.volume_rays);
    if (!estimate.usable()) {
      out.notes.push_back("volume check: the input's faces are too open to estimate their volume (" +
                          std::to_string(estimate.rays_paired) + " of " + std::to_string(estimate.rays_hit) +
                          " rays paired their crossings); no part was checked");
    } else {
      VolumeJudgement judged = judge_volumes(estimate, options, out);
      const double thinnest = thinnest_failing(estimate, *input.parts, judged);
      // A grid that could resolve the wall (4 cells across) but let the
      // outside in through an opening: close again, openings up to the wall's
      // thickness closed.
      if (options.resolve_thin_parts && judged.num_failing > 0 && out.grid_spacing_m > 0 &&
          thinnest >= 4 * out.grid_spacing_m) {
        CompletionInput hinted = input;
        hinted.thin_thickness_m = thinnest;
        Result<Completion> second = run_completer(hinted, completer, fallback, kept);
        if (!second.ok() && second.status().code() == StatusCode::kCancelled) return second.status();
        if (second.ok()) {
          VolumeJudgement again = judge_volumes(estimate, options, *second);
          char text[200];
          std::snprintf(text, sizeof text,
                        "tried again closing openings up to the %.3g mm thin wall the input measures: "
                        "volume error %.3g -> %.3g (%s)",
                        thinnest * 1000, judged.score, again.score, again.score < judged.score ? "kept" : "not kept");
          if (again.score < judged.score) {
            out = std::move(*second);
            judged = std::move(again);
          }
          out.notes.push_back(text);
        }
      }
      if (options.resolve_thin_parts && judged.num_failing > 0) try_thin_shells(input, estimate, options, judged, out);
      apply_judgement(estimate, options, judged, out);
    }
  }
  out.parts_volume_m3 = 0.0;
  for (const CompletedPart& p : out.parts) out.parts_volume_m3 += p.checks.volume_m3;
  if (kept.count == np) out.object_volume_m3 = out.parts_volume_m3;
  return out;
}

Result<Completion> complete_each_part(const CompletionInput& input, const std::string& backend,
                                      double max_relative_distance, const ClosePart& close) {
  if (input.mesh == nullptr || input.parts == nullptr)
    return Status::InvalidArgument(backend + ": needs the mesh and the parts");
  Completion result;
  for (std::size_t p = 0; p < input.parts->size(); ++p) {
    const Part& part = (*input.parts)[p];
    CompletedPart& out = result.parts.emplace_back();
    out.part = static_cast<int>(p);
    out.label = part.label;
    out.backend = backend;
    if (input.is_kept(p)) continue;  // complete() keeps it as given
    const Mesh patch = part_patch(*input.mesh, part);
    Status closed;
    try {
      closed = close(static_cast<int>(p), patch, out);
    } catch (const std::exception& e) {
      out.mesh = Mesh();
      closed = Status::Internal(backend + ": failed: " + e.what());
    }
    if (!closed.ok()) out.notes.push_back(closed.message());
    G2P_RETURN_IF_ERROR(input.report(static_cast<double>(p + 1) / static_cast<double>(input.parts->size()),
                                     "part " + std::to_string(p + 1) + "/" + std::to_string(input.parts->size())));
    if (out.mesh.num_faces() == 0) continue;
    out.checks = check_closed_mesh(out.mesh, &patch);
    const bool near = out.checks.relative_distance <= max_relative_distance;
    out.ok = closed.ok() && out.checks.watertight() && near;
    if (!out.checks.watertight()) {
      const MeshChecks& c = out.checks;
      out.notes.push_back(backend + ": the closed mesh failed the checks (" + (c.closed ? "" : "open, ") +
                          (c.manifold ? "" : "non-manifold, ") + (c.outward ? "" : "not outward, ") +
                          std::to_string(c.num_self_intersections) + " self-intersections)");
    }
    if (!near) {
      char text[160];
      std::snprintf(text, sizeof text, ": the closed mesh lies %.3g of the patch's diagonal from it (at most %.3g)",
                    out.checks.relative_distance, max_relative_distance);
      out.notes.push_back(backend + text);
    }
  }
  for (const CompletedPart& c : result.parts) result.parts_volume_m3 += c.checks.volume_m3;
  return result;
}

namespace {

nlohmann::json checks_json(const MeshChecks& c) {
  nlohmann::json j;
  j["watertight"] = c.watertight();
  j["closed"] = c.closed;
  j["manifold"] = c.manifold;
  j["outward"] = c.outward;
  j["self_intersections_checked"] = c.self_intersections_checked;
  j["self_intersection_free"] = c.self_intersection_free;
  j["num_self_intersections"] = c.num_self_intersections;
  j["num_components"] = c.num_components;
  j["volume_m3"] = c.volume_m3;
  j["area_m2"] = c.area_m2;
  j["max_distance_to_patch_m"] = c.max_distance_m;
  j["relative_distance_to_patch"] = c.relative_distance;
  return j;
}

}  // namespace

Status write_completion(const std::string& dir, const Completion& completion, const MaterialTable& table,
                        const std::vector<std::string>& formats) {
  for (const std::string& f : formats)
    if (f != "obj" && f != "ply" && f != "stl")
      return Status::InvalidArgument("write_completion: unknown mesh format '" + f + "' (obj, ply, stl)");
  G2P_RETURN_IF_ERROR(detail::ensure_directory(dir));
  nlohmann::json doc;
  doc["format"] = "g2p.completion";
  doc["version"] = 1;
  doc["object_volume_m3"] = completion.object_volume_m3;
  doc["parts_volume_m3"] = completion.parts_volume_m3;
  doc["grid_spacing_m"] = completion.grid_spacing_m;
  doc["input_volume_m3"] = completion.input_volume_m3;
  doc["kept_parts"] = completion.kept_parts;
  doc["notes"] = completion.notes;
  nlohmann::json parts = nlohmann::json::array();
  for (const CompletedPart& p : completion.parts) {
    const std::string name = table.valid_label(p.label) ? table[p.label].name : std::string("Unknown");
    nlohmann::json j;
    j["part"] = p.part;
    j["label"] = name;
    j["backend"] = p.backend;
    j["ok"] = p.ok;
    j["checks"] = checks_json(p.checks);
    j["input_volume_m3"] = p.input_volume_m3;
    j["volume_difference"] =
        std::isfinite(p.volume_difference) ? nlohmann::json(p.volume_difference) : nlohmann::json();
    j["notes"] = p.notes;
    j["vertices"] = p.mesh.num_vertices();
    j["triangles"] = p.mesh.num_faces();
    nlohmann::json files = nlohmann::json::object();
    if (p.mesh.num_faces() > 0)
      for (const std::string& f : formats) {
        const std::string file = "part_" + std::to_string(p.part) + "_" + name + "." + f;
        G2P_RETURN_IF_ERROR(write_mesh(dir + "/" + file, p.mesh));
        files[f] = file;
      }
    j["files"] = files;
    parts.push_back(j);
  }
  doc["parts"] = parts;
  return write_text_file(dir + "/completion.json", detail::json_text(doc, 2) + "\n");
}

}  // namespace g2p
