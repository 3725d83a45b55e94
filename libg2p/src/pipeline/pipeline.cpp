// Pipeline: the six stages of Gen2Physics (paper, Method) run in order on one
// model, each through its backend interface.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <new>
#include <utility>

#include "g2p/folder.h"
#include "g2p/pipeline.h"
#include "identify/kind_properties.h"
#include "pipeline/stage_clock.h"
#include "properties/report.h"
#include "segment/backends.h"

namespace g2p {

const StageReport* PipelineResult::stage(Stage s) const {
  for (const StageReport& r : stages)
    if (r.stage == s) return &r;
  return nullptr;
}

namespace {

// A backend given as an object, or created from its registry name.
template <typename Interface>
struct Slot {
  std::shared_ptr<Interface> custom;
  std::shared_ptr<Interface> made;  // from the name, by prepare()
  std::string made_from;            // the name and settings `made` was built with

  Interface* get() const { return custom ? custom.get() : made.get(); }
  std::string backend(const BackendChoice& choice) const { return custom ? "custom" : choice.name; }
};

std::string settings_key(const BackendChoice& c) {
  std::string key = c.name;
  for (const auto& [k, v] : c.settings) key += "\n" + k + "=" + v;
  return key;
}

// Creates `slot.made` from the choice unless a custom object is set or the
// same choice was built before.
template <typename Interface, typename Make>
Status prepare_slot(Slot<Interface>& slot, const BackendChoice& choice, const char* stage, Make make) {
  if (slot.custom) return Status::Ok();
  const std::string key = settings_key(choice);
  if (slot.made && slot.made_from == key) return Status::Ok();
  Result<std::unique_ptr<Interface>> made = make(choice);
  if (!made.ok()) return made.status().with_context(std::string(stage) + " backend '" + choice.name + "'");
  slot.made = std::move(*made);
  slot.made_from = key;
  return Status::Ok();
}

std::string fixed(double x, const char* format = "%.3g") {
  char b[32];
  std::snprintf(b, sizeof b, format, x);
  return b;
}

std::string fixed_mass(double kg) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g kg", kg);
  return b;
}

// Warnings a user should not miss in the finished asset: parts left out of
// it, and an object far larger or heavier (or smaller) than anything
// household or industrial, which almost always means a file in other units.
void plausibility_warnings(PipelineResult& r) {
  // What the importer recovered from or doubts (a normalised size among them).
  for (const std::string& w : r.model.info.warnings) r.warnings.push_back("import: " + w);
  std::vector<bool> exported(r.projection.parts.size(), false);
  for (const AssetPart& p : r.asset.parts)
    if (p.part >= 0 && p.part < static_cast<int>(exported.size())) exported[static_cast<std::size_t>(p.part)] = true;
  std::string missing;
  int left_out = 0;
  for (std::size_t i = 0; i < exported.size(); ++i) {
    if (exported[i]) continue;
    if (++left_out <= 12) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  }
  if (left_out > 0)
    r.warnings.push_back("export: " + std::to_string(left_out) + " of " + std::to_string(exported.size()) +
                         " parts are left out of the asset (no closed volume or no mass): part " + missing +
                         (left_out > 12 ? ", ..." : "") + "; report.json's notes say why for each");
  const double longest = bounds(r.model.mesh).sizes().maxCoeff();
  const double mass = r.asset.total.mass_kg;
  char what[160];
  std::snprintf(what, sizeof what, "%.3g kg and %.3g m long", mass, longest);
  // The kind's usual mass: the plausibility check once the object is known,
  // at the object's size where the kind's mass posterior scaled it.
  const bool scaled = r.properties.kind_range_kg[1] > 0.0;
  const double lo = scaled ? r.properties.kind_range_kg[0] : r.kind.mass_kg[0];
  const double hi = scaled ? r.properties.kind_range_kg[1] : r.kind.mass_kg[1];
  if (!r.kind.name.empty() && mass > 0.0 && (mass < lo || mass > hi)) {
    char range[96];
    if (scaled)
      std::snprintf(range, sizeof range, "%.3g-%.3g kg at %.3g m long", lo, hi, longest);
    else
      std::snprintf(range, sizeof range, "%.3g-%.3g kg", lo, hi);
    const bool vowel = std::string("aeiou").find(r.kind.name.front()) != std::string::npos;
    r.warnings.push_back("mass: the object weighs " + fixed_mass(mass) + ", outside " + (vowel ? "an " : "a ") +
                         r.kind.name + "'s usual " + range +
                         " (the object table): check its size (--height, --longest-side), the parts' classes and "
                         "their structure, or what it is (--object)");
  }
  if (r.model.info.looks_normalised) return;  // the import warning names the cause and the flags
  if (longest > 30.0 || mass > 50000.0)
    r.warnings.push_back(std::string("the object is ") + what +
                         ", far beyond household and industrial objects: is the file in centimetres or "
                         "millimetres? Give its unit (g2p run --unit cm or --unit mm; ImportOptions::unit_scale)");
  else if (longest < 0.005 || mass < 1e-4)
    r.warnings.push_back(std::string("the object is ") + what +
                         ", smaller than anything it is likely to be: is the file in another unit? Give its "
                         "unit (g2p run --unit; ImportOptions::unit_scale)");
}

}  // namespace

struct Pipeline::Impl {
  PipelineOptions options;
  MaterialTable table = MaterialTable::paper_default();
  Slot<Renderer> renderer;
  Slot<Identifier> identifier;
  std::unique_ptr<ObjectTable> objects;  // a caller's; null: ObjectTable::shipped()
  Slot<Segmenter> segmenter;
  Slot<Refiner> refiner;
  Slot<Completer> completer;
  Slot<Completer> fallback;
  Slot<PropertyEstimator> estimator;
  Slot<Decomposer> decomposer;

  struct RunState;
  Status run_stages(PipelineResult& r, RunContext& context, Stage first, Stage last);
  Status render_views(RunState& s);
  Status identify_object(RunState& s);
  void assume_kind_size(PipelineResult& r, const std::string& said, StageReport& report) const;
  void prepare_class_prior(RunState& s) const;
  Status segment_views(RunState& s);
  Status project_labels(RunState& s);
  Status refine_labels(RunState& s);
  Status apply_corrections(RunState& s, bool apply_classes);
  void fit_classes(RunState& s) const;
  std::vector<bool> class_pinned(const RunState& s) const;
  Status complete_parts(RunState& s);
  Status estimate(RunState& s);
  Status decompose_collision(RunState& s);
  Status build_asset(RunState& s);
  const ObjectTable& object_table() const { return objects ? *objects : ObjectTable::shipped(); }
};

Pipeline::Pipeline(PipelineOptions options) : impl_(std::make_unique<Impl>()) { impl_->options = std::move(options); }
Pipeline::~Pipeline() = default;
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;

const PipelineOptions& Pipeline::options() const { return impl_->options; }
PipelineOptions& Pipeline::options() { return impl_->options; }

void Pipeline::set_renderer(std::shared_ptr<Renderer> r) { impl_->renderer.custom = std::move(r); }
void Pipeline::set_identifier(std::shared_ptr<Identifier> i) { impl_->identifier.custom = std::move(i); }
void Pipeline::set_object_table(ObjectTable table) { impl_->objects = std::make_unique<ObjectTable>(std::move(table)); }
void Pipeline::set_segmenter(std::shared_ptr<Segmenter> s) { impl_->segmenter.custom = std::move(s); }
void Pipeline::set_refiner(std::shared_ptr<Refiner> r) { impl_->refiner.custom = std::move(r); }
void Pipeline::set_completer(std::shared_ptr<Completer> c) { impl_->completer.custom = std::move(c); }
void Pipeline::set_estimator(std::shared_ptr<PropertyEstimator> e) { impl_->estimator.custom = std::move(e); }
void Pipeline::set_decomposer(std::shared_ptr<Decomposer> d) { impl_->decomposer.custom = std::move(d); }
void Pipeline::set_material_table(MaterialTable table) { impl_->table = std::move(table); }
const MaterialTable& Pipeline::material_table() const { return impl_->table; }

Status Pipeline::prepare() {
  Impl& m = *impl_;
  const PipelineOptions& o = m.options;
  if (m.table.size() == 0) return Status::InvalidArgument("pipeline: the material table has no classes");
  G2P_RETURN_IF_ERROR(prepare_slot(m.renderer, o.renderer, "render", [](const BackendChoice& c) {
    if (!c.settings.empty())
      return Result<std::unique_ptr<Renderer>>(
          Status::InvalidArgument("renderers take no settings (got '" + c.settings.begin()->first + "')"));
    return renderer_registry().create(c.name);
  }));
  G2P_RETURN_IF_ERROR(prepare_slot(m.identifier, o.identifier, "identify",
                                   [](const BackendChoice& c) { return make_identifier(c.name, c.settings); }));
  if (!(o.kind_prior > 0.0 && o.kind_prior <= 1.0))
    return Status::InvalidArgument("pipeline: --kind-prior must lie in (0, 1] (PipelineOptions::kind_prior)");
  if (!(o.kind_confidence >= 0.0 && o.kind_confidence <= 1.0))
    return Status::InvalidArgument("pipeline: --kind-confidence must lie in [0, 1] (PipelineOptions::kind_confidence)");
  if (m.object_table().size() == 0)
    return Status::Internal("pipeline: the shipped object table did not load (libg2p/data/objects.json)");
  if (!o.object.empty()) {  // the user's words must name a kind: said before any work
    Result<std::string> kind = kind_from_text(m.object_table(), o.object);
    if (!kind.ok()) return kind.status();
  }
  if (!o.overrides.object.empty()) {
    Result<std::string> kind = kind_from_text(m.object_table(), o.overrides.object, "the overrides' \"object\"");
    if (!kind.ok()) return kind.status();
  }
  G2P_RETURN_IF_ERROR(prepare_slot(m.segmenter, o.segmenter, "segment",
                                   [](const BackendChoice& c) { return make_segmenter(c.name, c.settings); }));
  G2P_RETURN_IF_ERROR(prepare_slot(m.refiner, o.refiner, "refine",
                                   [](const BackendChoice& c) { return make_refiner(c.name, c.settings); }));
  G2P_RETURN_IF_ERROR(prepare_slot(m.completer, o.completer, "complete",
                                   [](const BackendChoice& c) { return make_completer(c.name, c.settings); }));
  if (!o.completion_fallback.empty() && (m.completer.custom || o.completion_fallback != o.completer.name)) {
    G2P_RETURN_IF_ERROR(prepare_slot(m.fallback, BackendChoice{o.completion_fallback, {}}, "complete fallback",
                                     [](const BackendChoice& c) { return make_completer(c.name, c.settings); }));
  } else {
    m.fallback.made.reset();
    m.fallback.made_from.clear();
  }
  G2P_RETURN_IF_ERROR(prepare_slot(m.estimator, o.estimator, "properties",
                                   [](const BackendChoice& c) { return make_estimator(c.name, c.settings); }));
  G2P_RETURN_IF_ERROR(prepare_slot(m.decomposer, o.decomposer, "decompose",
                                   [](const BackendChoice& c) { return make_decomposer(c.name, c.settings); }));
  G2P_RETURN_IF_ERROR(validate(o.decompose).with_context("pipeline"));
  if (o.last_stage == Stage::kLoad)
    return Status::InvalidArgument("pipeline: last_stage must be render or a later stage (load is not a stage of run)");
  const ViewOptions& v = o.views;
  if (v.num_views < 1 || v.width < 8 || v.height < 8)
    return Status::InvalidArgument("pipeline: views need at least 1 view of 8 x 8 pixels (got " +
                                   std::to_string(v.num_views) + " of " + std::to_string(v.width) + " x " +
                                   std::to_string(v.height) + ")");
  for (const std::string& f : o.formats)
    if (f != "mjcf" && f != "urdf" && f != "sdf" && f != "glb")
      return Status::InvalidArgument("pipeline: unknown export format '" + f + "' (mjcf, urdf, sdf, glb)");
  return Status::Ok();
}

// ---- The stages, one function each ----------------------------------------------

// What one run carries from stage to stage besides its result.
struct Pipeline::Impl::RunState {
  PipelineResult& r;
  RunContext& context;
  // The object's kind's materials as a prior over the classes the image
  // decides (kind_class_prior); empty: none.
  std::vector<float> class_prior;
  std::vector<std::string> prior_classes;  // the classes the kind lists, for the notes
  // The corrections, resolved on the final parts (for the estimator).
  std::unique_ptr<ResolvedOverrides> resolved;

  void finish(detail::StageClock& clock) {
    r.stages.push_back(clock.finish());
    r.peak_rss_bytes = std::max(r.peak_rss_bytes, r.stages.back().peak_rss_bytes);
  }
};

// 1. render: the views, each with its face-ID and material buffers.
Status Pipeline::Impl::render_views(RunState& s) {
  PipelineResult& r = s.r;
  detail::StageClock clock(Stage::kRender, renderer.backend(options.renderer), options.measure_stage_memory);
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kRender, 0.0, "cameras"));
  Result<std::vector<Camera>> cameras = make_views(r.model.mesh, options.views);
  if (!cameras.ok()) return cameras.status().with_context("render");
  G2P_RETURN_IF_ERROR(renderer.get()->set_model(r.model).with_context("render"));
  const std::size_t n = cameras->size();
  r.views.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    G2P_RETURN_IF_ERROR(renderer.get()
                            ->render_into((*cameras)[i], options.render, r.views[i])
                            .with_context("render: view " + std::to_string(i)));
    G2P_RETURN_IF_ERROR(s.context.report(Stage::kRender, double(i + 1) / double(n),
                                         "view " + std::to_string(i + 1) + "/" + std::to_string(n)));
  }
  s.finish(clock);
  return Status::Ok();
}

// The kind's materials weigh the classes the image decides (segment, refine).
void Pipeline::Impl::prepare_class_prior(RunState& s) const {
  if (s.r.kind.name.empty() || !s.class_prior.empty()) return;
  s.class_prior = kind_class_prior(s.r.kind, s.r.table, options.kind_prior, &s.prior_classes);
}

// 2. segment: a material class per pixel.
Status Pipeline::Impl::segment_views(RunState& s) {
  PipelineResult& r = s.r;
  const PipelineOptions& o = options;
  detail::StageClock clock(Stage::kSegment, segmenter.backend(o.segmenter), o.measure_stage_memory);
  G2P_RETURN_IF_ERROR(segmenter.get()->set_model(r.model, r.table).with_context("segment"));
  // A backend that degraded (`hybrid` falls back to `pbr` without its network) says why.
  for (const std::string& w : segmenter.get()->warnings()) r.warnings.push_back("segment: " + w);
  r.image_decided = segmenter.get()->image_decided_faces();
  prepare_class_prior(s);
  std::size_t prior_changed = 0;
  const std::size_t n = r.views.size();
  r.label_maps.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    G2P_RETURN_IF_ERROR(
        segmenter.get()->segment_into(r.views[i], r.label_maps[i]).with_context("segment: view " + std::to_string(i)));
    if (!s.class_prior.empty()) {
      Result<std::size_t> changed = apply_class_prior(s.class_prior, r.image_decided, r.views[i], r.label_maps[i]);
      if (!changed.ok()) return changed.status().with_context("segment: view " + std::to_string(i));
      prior_changed += *changed;
    }
    G2P_RETURN_IF_ERROR(s.context.report(Stage::kSegment, double(i + 1) / double(n),
                                         "view " + std::to_string(i + 1) + "/" + std::to_string(n)));
  }
  if (!s.class_prior.empty()) {
    std::string classes;
    for (const std::string& c : s.prior_classes) classes += (classes.empty() ? "" : ", ") + c;
    clock.report().notes.push_back("the " + r.kind.name + "'s usual materials (" + classes +
                                   ") weigh the classes read from the image, every other class x" +
                                   fixed(o.kind_prior) + " (--kind-prior): " + std::to_string(prior_changed) +
                                   " pixels changed class");
  }
  s.finish(clock);
  return Status::Ok();
}

// 3. project: votes over all views, flood fill, connected parts.
Status Pipeline::Impl::project_labels(RunState& s) {
  PipelineResult& r = s.r;
  const Mesh& mesh = r.model.mesh;
  detail::StageClock clock(Stage::kProject, "vote", options.measure_stage_memory);
  Result<Projection> projection = project(mesh, r.views, r.label_maps, r.table.size(), options.project);
  if (!projection.ok()) return projection.status().with_context("project");
  r.projection = std::move(*projection);
  r.projected_labels = r.projection.labels.label;
  std::size_t seen = 0;
  for (std::uint8_t v : r.projection.labels.seen) seen += v;
  clock.report().notes.push_back(std::to_string(seen) + " of " + std::to_string(mesh.num_faces()) + " faces seen, " +
                                 std::to_string(r.projection.parts.size()) + " parts");
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kProject, 1.0, std::to_string(r.projection.parts.size()) + " parts"));
  s.finish(clock);
  return Status::Ok();
}

// 4. refine (optional): a failure keeps the projected labels.
Status Pipeline::Impl::refine_labels(RunState& s) {
  PipelineResult& r = s.r;
  const PipelineOptions& o = options;
  if (!refiner.custom && o.refiner.name == "none") return Status::Ok();
  const Mesh& mesh = r.model.mesh;
  detail::StageClock clock(Stage::kRefine, refiner.backend(o.refiner), o.measure_stage_memory);
  prepare_class_prior(s);
  RefineInput in{&mesh,    &r.projection.graph, &r.projection.votes, &r.projection.labels, &r.views,
                 &r.table, &r.image_decided,    &s.class_prior};
  Result<RefineResult> refined = refiner.get()->refine(in);
  const StatusCode code = refined.ok() ? StatusCode::kOk : refined.status().code();
  if (code == StatusCode::kInvalidArgument || code == StatusCode::kNotFound)
    return refined.status().with_context("refine");  // its settings are wrong: the caller must fix them
  Status applied =
      refined.ok() ? apply_refinement(mesh, refined->labels, o.project.partition, r.projection) : refined.status();
  StageReport& report = clock.report();
  if (applied.ok() && refined->fell_back) {
    report.ok = false;
    report.error = refined->notes.empty() ? "the backend kept the input labels" : refined->notes.back();
    // A backend that fell back to another one (regions to smooth) still changed labels.
    r.warnings.push_back("refine (" + report.backend + ") " +
                         (refined->changes.empty() ? "failed; the projected labels stand: " : "degraded: ") +
                         report.error);
    r.refinement = std::move(*refined);
  } else if (!applied.ok()) {
    report.ok = false;
    report.error = applied.to_string();
    r.warnings.push_back("refine (" + report.backend + ") failed; the projected labels stand: " + report.error);
  } else {
    report.notes = refined->notes;
    report.notes.push_back(std::to_string(refined->changes.size()) + " faces changed, " +
                           std::to_string(r.projection.parts.size()) + " parts");
    r.refinement = std::move(*refined);
  }
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kRefine, 1.0, report.ok ? "done" : "failed, skipped"));
  s.finish(clock);
  return Status::Ok();
}

// A person's corrections, after refine: the state's own (a folder's
// overrides.json, already applied to its labels) and then options().overrides.
// Classes change here (the parts re-form) when `apply_classes`; structure,
// wall thickness and density go to the estimator through `s.resolved`.
Status Pipeline::Impl::apply_corrections(RunState& s, bool apply_classes) {
  PipelineResult& r = s.r;
  const Mesh& mesh = r.model.mesh;
  std::vector<Overrides> files;
  if (!r.overrides.empty()) files.push_back(r.overrides);
  if (!options.overrides.empty()) files.push_back(options.overrides);
  if (files.empty()) return Status::Ok();
  Overrides combined;
  std::vector<std::string> notes;
  for (const Overrides& file : files) {
    Result<ResolvedOverrides> res =
        resolve_overrides(file, mesh.num_faces(), r.projection.parts, r.projection.labels.label, r.table);
    if (!res.ok()) return res.status();
    if (apply_classes) {
      Result<std::vector<std::string>> applied = apply_class_overrides(*res, mesh, r.projection, r.table);
      if (!applied.ok()) return applied.status();
      notes.insert(notes.end(), applied->begin(), applied->end());
    }
    Overrides selections = as_face_selections(*res);
    if (files.size() == 1) {  // the usual case: one file, resolved once
      s.resolved = std::make_unique<ResolvedOverrides>(std::move(*res));
      combined = std::move(selections);
      break;
    }
    combined.faces_total = selections.faces_total;
    if (combined.model.empty()) combined.model = selections.model;
    if (!selections.object.empty()) combined.object = selections.object;
    for (Override& e : selections.entries) combined.entries.push_back(std::move(e));
  }
  if (!s.resolved) {  // face selections without checks always resolve
    Result<ResolvedOverrides> res =
        resolve_overrides(combined, mesh.num_faces(), r.projection.parts, r.projection.labels.label, r.table);
    if (!res.ok()) return res.status();
    s.resolved = std::make_unique<ResolvedOverrides>(std::move(*res));
  }
  if (!options.overrides.object.empty())  // what the object is (identify or resume applied it)
    notes.push_back("the object is taken for what the overrides' \"object\" says, '" + options.overrides.object + "'");
  r.overrides_applied = std::move(notes);
  r.overrides = std::move(combined);
  return Status::Ok();
}

// Per part: a person gave its class (a correction), so it is not in doubt.
std::vector<bool> Pipeline::Impl::class_pinned(const RunState& s) const {
  const PipelineResult& r = s.r;
  std::vector<bool> pinned(r.projection.parts.size(), false);
  if (s.resolved)
    for (std::size_t i = 0; i < r.projection.parts.size(); ++i)
      for (int f : r.projection.parts[i].faces)
        if (f >= 0 && static_cast<std::size_t>(f) < s.resolved->class_entry.size() &&
            s.resolved->class_entry[static_cast<std::size_t>(f)] >= 0)
          pinned[i] = true;
  return pinned;
}

// The kind's share of each class (posterior.h), after the corrections: the
// parts a person gave a class keep it.
void Pipeline::Impl::fit_classes(RunState& s) const {
  PipelineResult& r = s.r;
  if (!options.kind_posterior || r.kind.name.empty()) return;
  const std::vector<bool> pinned = class_pinned(s);
  const std::vector<std::string> notes = fit_classes_to_kind(r.projection, r.kind, r.table, pinned, options.posterior);
  if (notes.empty()) return;
  for (StageReport& stage : r.stages)
    if (stage.stage == Stage::kRefine)
      for (const std::string& n : notes) stage.notes.push_back("the kind's classes: " + n);
  r.kind_class_changes = notes;
}

// 5. complete: every part closed into a watertight volume.
Status Pipeline::Impl::complete_parts(RunState& s) {
  PipelineResult& r = s.r;
  detail::StageClock clock(Stage::kComplete, completer.backend(options.completer), options.measure_stage_memory);
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kComplete, 0.0, std::to_string(r.projection.parts.size()) + " parts"));
  CompletionInput input;
  input.mesh = &r.model.mesh;
  input.parts = &r.projection.parts;
  input.table = &r.table;
  RunContext& context = s.context;
  input.progress = [&context](double fraction, const std::string& message) {
    return context.report(Stage::kComplete, fraction, message);
  };
  CompletionOptions completion_options;
  completion_options.weld_tolerance = options.project.weld_tolerance;
  completion_options.keep_closed_parts = options.keep_closed_parts;
  completion_options.resolve_thin_parts = options.resolve_thin_parts;
  Result<Completion> done = complete(input, *completer.get(), fallback.get(), completion_options);
  if (!done.ok()) return done.status().with_context("complete");
  r.completion = std::move(*done);
  int closed = 0;
  for (const CompletedPart& p : r.completion.parts) {
    closed += p.ok ? 1 : 0;
    // A volume the input disagrees with is a mass the user must not trust.
    for (const std::string& n : p.notes)
      if (n.rfind("volume check: ", 0) == 0 && n.rfind("volume check: not judged alone", 0) != 0)
        r.warnings.push_back("complete: part " + std::to_string(p.part) + " (" +
                             (r.table.valid_label(p.label) ? r.table[p.label].name : std::string("Unknown")) +
                             "): " + n.substr(14) + "; its mass follows its closed volume");
  }
  for (const std::string& n : r.completion.notes)  // the object's volume against the input's
    if (n.rfind("volume check: ", 0) == 0)
      r.warnings.push_back("complete: " + n.substr(14) + "; the mass follows the closed parts");
  clock.report().notes = r.completion.notes;
  clock.report().notes.push_back(std::to_string(closed) + " of " + std::to_string(r.completion.parts.size()) +
                                 " parts closed and checked");
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kComplete, 1.0, std::to_string(closed) + " parts closed"));
  s.finish(clock);
  return Status::Ok();
}

// 6. properties: density, solid or hollow, mass properties.
Status Pipeline::Impl::estimate(RunState& s) {
  PipelineResult& r = s.r;
  const PipelineOptions& o = options;
  const Mesh& mesh = r.model.mesh;
  detail::StageClock clock(Stage::kProperties, estimator.backend(o.estimator), o.measure_stage_memory);
  std::unique_ptr<PropertyEstimator> overriding;
  if (s.resolved && r.overrides.changes_properties())
    overriding = make_overriding_estimator(*estimator.get(), *s.resolved);
  const PropertyEstimator& chosen = overriding ? *overriding : *estimator.get();
  const std::vector<View>* views = r.views.empty() ? nullptr : &r.views;
  RunContext& context = s.context;
  const StageProgress progress = [&context](double fraction, const std::string& message) {
    return context.report(Stage::kProperties, fraction, message);
  };
  // The object's rays, built once for every weighing below.
  Result<std::shared_ptr<const SurfaceRays>> rays = SurfaceRays::build(mesh);
  if (!rays.ok()) return rays.status().with_context("properties");
  Result<PropertiesReport> report =
      o.kind_properties && !r.kind.name.empty()
          ? detail::estimate_properties_of_kind(mesh, r.projection.parts, r.completion, r.table, chosen, r.kind, views,
                                                progress, **rays)
          : detail::estimate_properties(mesh, r.projection.parts, r.completion, r.table, chosen, views, progress,
                                        **rays);
  if (!report.ok()) return report.status().with_context("properties");
  // The kind's mass (or, of an unknown kind, everyday objects' bulk density):
  // each part's structure chosen against it, weighed again where the choice
  // differs from the estimator's.
  if (o.kind_posterior) {
    const bool of_kind = !r.kind.name.empty();
    ClassEvidence classes;
    classes.votes = &r.projection.votes;
    classes.pinned = class_pinned(s);
    const double longest = bounds(mesh).sizes().maxCoeff();
    Result<MassPosterior> posterior =
        of_kind ? fit_mass_to_kind(r.projection.parts, r.completion, r.table, *report, r.kind, longest, o.posterior,
                                   classes)
                : fit_mass_to_bulk_density(r.projection.parts, r.completion, r.table, *report, o.posterior, classes);
    if (!posterior.ok()) {
      // A kind the user gave or the views named is worth a warning; the weak
      // belief of an unknown kind a note.
      if (of_kind)
        r.warnings.push_back("properties: the kind's mass was not judged: " + posterior.status().message());
      else
        report->notes.push_back("everyday objects' mass: not judged: " + posterior.status().message());
    } else {
      if (posterior->changed()) {
        std::unique_ptr<PropertyEstimator> by_posterior = make_posterior_estimator(chosen, *posterior);
        Result<PropertiesReport> again =
            o.kind_properties && of_kind
                ? detail::estimate_properties_of_kind(mesh, r.projection.parts, r.completion, r.table, *by_posterior,
                                                      r.kind, views, progress, **rays)
                : detail::estimate_properties(mesh, r.projection.parts, r.completion, r.table, *by_posterior, views,
                                              progress, **rays);
        if (!again.ok()) return again.status().with_context("properties");
        report = std::move(again);
      }
      apply_intervals(*posterior, *report);
      for (const std::string& n : r.kind_class_changes) report->notes.push_back("kind's classes: " + n);
    }
  }
  r.properties = std::move(*report);
  r.properties.size = object_size(r.model);
  if (s.resolved)
    for (const PartReport& p : r.properties.parts) {
      // A fill the part could not take is named beside its correction, so
      // that the list never claims contents the report left out.
      std::string left_out;
      for (const std::string& n : p.properties.notes)
        if (n.rfind(kContentsLeftOut, 0) == 0) left_out = "; " + n;
      for (const std::string& n : p.properties.notes)
        if (n.rfind("correction: ", 0) == 0)  // "part 2: hollow, 3 mm walls", as the class changes read
          r.overrides_applied.push_back("part " + std::to_string(p.part) + ": " + n.substr(12) + left_out);
    }
  clock.report().notes = r.properties.notes;
  for (const std::string& n : r.properties.notes)  // contents asked for and not given; the kind's hidden mass
    if (n.find(kContentsLeftOut) != std::string::npos || n.rfind("hidden mass left out", 0) == 0)
      r.warnings.push_back("properties: " + n);
  // The vlm estimator never fails a part: it falls back to the table, which
  // is a degraded optional stage the caller should hear about.
  if (!estimator.custom && o.estimator.name == "vlm") {
    int fell_back = 0, weighed = 0;
    std::string why;
    for (const PartReport& p : r.properties.parts) {
      if (p.mass.mass_kg <= 0) continue;
      ++weighed;
      if (p.properties.density_source == ValueSource::kVlm) continue;
      ++fell_back;
      if (why.empty() && !p.properties.notes.empty()) why = p.properties.notes.back();
    }
    if (fell_back > 0) {
      const std::string what = std::to_string(fell_back) + " of " + std::to_string(weighed) +
                               " parts fell back to the table's values" + (why.empty() ? "" : " (" + why + ")");
      r.warnings.push_back("properties (vlm): " + what);
      if (fell_back == weighed) {
        clock.report().ok = false;
        clock.report().error = what;
      }
    }
  }
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kProperties, 1.0, "done"));
  s.finish(clock);
  return Status::Ok();
}

// 7. decompose: every part's collision geometry, convex hulls for engines.
Status Pipeline::Impl::decompose_collision(RunState& s) {
  PipelineResult& r = s.r;
  const PipelineOptions& o = options;
  detail::StageClock clock(Stage::kDecompose, decomposer.backend(o.decomposer), o.measure_stage_memory);
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kDecompose, 0.0, std::to_string(r.completion.parts.size()) + " parts"));
  RunContext& context = s.context;
  Status stopped;  // the run's answer to a part's report, when it says stop
  r.collision =
      decompose_parts(r.completion, *decomposer.get(), o.decompose, decomposer.backend(o.decomposer), &r.model.mesh,
                      &r.projection.parts, [&context, &stopped](double fraction, const std::string& message) {
                        Status answer = context.report(Stage::kDecompose, fraction, message);
                        if (!answer.ok() && stopped.ok()) stopped = answer;
                        return answer;
                      });
  if (!stopped.ok()) return stopped;
  int hulls = 0, fell_back = 0, none = 0, uncovering = 0;
  for (std::size_t i = 0; i < r.collision.size(); ++i) {
    const ConvexDecomposition& d = r.collision[i];
    hulls += static_cast<int>(d.hulls.size());
    fell_back += d.fell_back ? 1 : 0;
    const bool weighed = i < r.properties.parts.size() && r.properties.parts[i].mass.mass_kg > 0;
    if (d.hulls.empty() && weighed) ++none;
    // Beyond the tolerance with the whole budget spent: a part the backend
    // finished early (the `hull` backend's every part) has its note only.
    if (!d.hulls.empty() && static_cast<int>(d.hulls.size()) >= d.hull_budget &&
        std::max(d.max_distance_m, d.uncovered_max_m) > d.coverage_tolerance_m)
      ++uncovering;
    for (const std::string& n : d.notes) clock.report().notes.push_back("part " + std::to_string(i) + ": " + n);
  }
  clock.report().notes.push_back(std::to_string(hulls) + " convex hulls for " + std::to_string(r.collision.size()) +
                                 " parts");
  if (fell_back + none > 0)
    r.warnings.push_back("decompose (" + clock.report().backend + "): " + std::to_string(fell_back) +
                         " parts fell back to their single convex hull and " + std::to_string(none) +
                         " have no collision shape (see report.json)");
  if (uncovering > 0)
    r.warnings.push_back("decompose (" + clock.report().backend + "): the hulls of " + std::to_string(uncovering) +
                         " parts stay farther from their surfaces than --coverage-tolerance with their whole hull "
                         "budget spent (see report.json's collision notes)");
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kDecompose, 1.0, std::to_string(hulls) + " hulls"));
  s.finish(clock);
  return Status::Ok();
}

// The simulation asset (written by write_pipeline_output).
Status Pipeline::Impl::build_asset(RunState& s) {
  PipelineResult& r = s.r;
  detail::StageClock clock(Stage::kExport, "asset", options.measure_stage_memory);
  std::string name = options.name;
  if (name.empty()) name = std::filesystem::path(r.model.info.path).stem().string();
  if (name.empty()) name = "object";
  Result<SimulationAsset> asset =
      make_asset(name, r.model.mesh, r.projection.parts, r.completion, r.properties, r.table, r.collision);
  if (!asset.ok()) return asset.status().with_context("export");
  r.asset = std::move(*asset);
  r.asset.identification_json = identification_json(r.identification, object_table(), r.size_assumed_m);
  clock.report().notes = r.asset.notes;
  plausibility_warnings(r);
  G2P_RETURN_IF_ERROR(s.context.report(Stage::kExport, 1.0, r.asset.name));
  s.finish(clock);
  return Status::Ok();
}

Status Pipeline::Impl::run_stages(PipelineResult& r, RunContext& context, Stage first, Stage last) {
  RunState s{r, context, {}, {}, {}};
  using Step = Status (Impl::*)(RunState&);
  struct Entry {
    Stage stage;
    Step step;
  };
  static constexpr Entry kSteps[] = {
      {Stage::kRender, &Impl::render_views},   {Stage::kIdentify, &Impl::identify_object},
      {Stage::kSegment, &Impl::segment_views}, {Stage::kProject, &Impl::project_labels},
      {Stage::kRefine, &Impl::refine_labels},  {Stage::kComplete, &Impl::complete_parts},
      {Stage::kProperties, &Impl::estimate},   {Stage::kDecompose, &Impl::decompose_collision},
      {Stage::kExport, &Impl::build_asset}};
  for (const Entry& e : kSteps) {
    if (e.stage > last) break;
    if (e.stage >= first) G2P_RETURN_IF_ERROR((this->*e.step)(s));
    // The corrections follow refine, and the estimator needs them resolved
    // even when the run starts after complete.
    if (e.stage == Stage::kRefine && first <= Stage::kProperties)
      G2P_RETURN_IF_ERROR(apply_corrections(s, /*apply_classes=*/first <= Stage::kComplete));
    if (e.stage == Stage::kRefine && first <= Stage::kComplete && last >= Stage::kComplete) fit_classes(s);
    if (e.stage >= first || r.last_stage < e.stage) r.last_stage = e.stage;
  }
  return Status::Ok();
}

namespace {

// Scales a rendered run about the origin: the mesh, and the views' cameras
// and depths, so that the views stay the views of the scaled mesh.
void scale_run(PipelineResult& r, double s) {
  for (Eigen::Vector3f& p : r.model.mesh.positions) p = (p.cast<double>() * s).cast<float>();
  ImportInfo& info = r.model.info;
  info.unit_scale_m *= s;
  info.file_to_model.topLeftCorner<3, 3>() *= s;
  for (View& v : r.views) {
    v.camera.position *= s;
    if (v.camera.orthographic) {
      v.camera.fx /= s;
      v.camera.fy /= s;
    }
    for (float& d : v.depth.storage())
      if (std::isfinite(d)) d = static_cast<float>(d * s);
  }
}

}  // namespace

// A normalised mesh with no size given takes its kind's typical longest side,
// when the kind is confident enough and the policy allows; the import's
// warning says what was assumed, or why not.
void Pipeline::Impl::assume_kind_size(PipelineResult& r, const std::string& said, StageReport& report) const {
  ImportInfo& info = r.model.info;
  if (info.scale_source != "file") return;
  const PipelineOptions& o = options;
  const Identification& ident = r.identification;
  const bool confident = !r.kind.name.empty();
  // A size the kind excludes (a 1.9 m camera, a 1.5 m toy train) is no more
  // the object's than a normalised one (kKindSizeTolerance).
  if (!info.looks_normalised) {
    const double longest = bounds(r.model.mesh).sizes().maxCoeff();
    const std::array<double, 2>& usual = r.kind.longest_side_m;
    if (!confident || o.size_policy != SizePolicy::kKind || !(usual[0] > 0.0) || !(longest > 0.0) ||
        !std::isfinite(longest) ||
        (longest >= usual[0] / kKindSizeTolerance && longest <= usual[1] * kKindSizeTolerance))
      return;
    const double target = r.kind.typical_longest_side_m;
    if (!(target > 0.0)) return;
    scale_run(r, target / longest);
    r.kind_scale = target / longest;
    info.scale_source = "kind";
    r.size_assumed_m = target;
    info.warnings.push_back("the file says the object is " + fixed(longest) + " m long, outside " +
                            (std::string("aeiou").find(r.kind.name.front()) != std::string::npos ? "an " : "a ") +
                            r.kind.name + "'s usual " + fixed(usual[0]) + "-" + fixed(usual[1]) +
                            " m, and it is identified as " + said + ": it is scaled to a " + r.kind.name +
                            "'s typical longest side, " + fixed(target) +
                            " m (the object table). Give the real size with --height or --longest-side, or keep the "
                            "file's with --size-from file (PipelineOptions::size_policy)");
    report.notes.push_back("size assumed: longest side " + fixed(target) + " m, a " + r.kind.name + "'s (the file's " +
                           fixed(longest) + " m is outside its usual range)");
    return;
  }
  auto normalised_warning = [&info] {
    return std::find_if(info.warnings.begin(), info.warnings.end(),
                        [](const std::string& w) { return w.rfind("the model looks normalised", 0) == 0; });
  };
  const auto it = normalised_warning();
  if (o.size_policy == SizePolicy::kKind && confident) {
    const double longest = bounds(r.model.mesh).sizes().maxCoeff();
    const double target = r.kind.typical_longest_side_m;
    if (longest > 0.0 && std::isfinite(longest) && target > 0.0) {
      scale_run(r, target / longest);
      r.kind_scale = target / longest;
      info.scale_source = "kind";
      r.size_assumed_m = target;
      const std::string text =
          "the model looks normalised (its longest side was " + fixed(longest) + " m) and is identified as " + said +
          ": it is scaled to a " + r.kind.name + "'s typical longest side, " + fixed(target) +
          " m (the object table). Give the real size with --height or --longest-side, or keep the file's with "
          "--size-from file (PipelineOptions::size_policy)";
      if (it != info.warnings.end())
        *it = text;
      else
        info.warnings.push_back(text);
      report.notes.push_back("size assumed: longest side " + fixed(target) + " m, a " + r.kind.name + "'s");
    }
  } else if (it != info.warnings.end()) {
    if (o.size_policy == SizePolicy::kFile)
      *it += "; its size is kept as the file's (--size-from file)";
    else if (ident.known())
      *it += "; identified as " + said + ", below the " + fixed(100.0 * o.kind_confidence, "%.0f") +
             " % needed to assume its size (--kind-confidence)";
    else
      *it += "; what the object is could not be told (give it with --object to assume its kind's size)";
  }
}

Status Pipeline::Impl::identify_object(RunState& s) {
  PipelineResult& r = s.r;
  RunContext& context = s.context;
  const PipelineOptions& o = options;
  detail::StageClock clock(Stage::kIdentify, identifier.backend(o.identifier), o.measure_stage_memory);
  G2P_RETURN_IF_ERROR(context.report(Stage::kIdentify, 0.0, "identifying"));
  const ObjectTable& objects_in_use = object_table();
  IdentifyInput in;
  in.model = &r.model;
  in.views = &r.views;
  in.renderer = renderer.get();  // its model is r.model, as rendered
  in.table = &objects_in_use;
  // The user's words: --object, else a correction's "object" (overrides.json).
  const bool corrected = o.object.empty() && !o.overrides.object.empty();
  in.object_text = corrected ? o.overrides.object : o.object;
  in.use_file_name = !o.anonymize_names;
  Result<Identification> id = identifier.get()->identify(in);
  if (id.ok() && corrected)
    for (KindGuess& g : id->candidates)
      if (g.source == "object") {
        g.source = "override";
        g.evidence = "overrides \"object\": '" + o.overrides.object + "'";
      }
  if (id.ok() && !o.object.empty() && !o.overrides.object.empty())
    id->notes.push_back("the overrides' \"object\" ('" + o.overrides.object + "') is not used: --object ('" + o.object +
                        "') wins");
  StageReport& report = clock.report();
  if (!id.ok()) {
    const StatusCode code = id.status().code();
    if (code == StatusCode::kInvalidArgument || code == StatusCode::kNotFound || code == StatusCode::kCancelled)
      return id.status().with_context("identify");  // the user's words or settings: theirs to fix
    report.ok = false;
    report.error = id.status().to_string();
    r.warnings.push_back("identify (" + report.backend + ") failed; the object is taken as unknown: " + report.error);
  } else {
    r.identification = std::move(*id);
  }
  const Identification& ident = r.identification;
  for (const std::string& w : ident.warnings) r.warnings.push_back("identify: " + w);
  report.notes = ident.notes;
  // The run acts on the kind only when it is confident enough.
  const int k = ident.known() && ident.confidence() >= o.kind_confidence ? objects_in_use.find(ident.kind()) : -1;
  if (k >= 0) r.kind = objects_in_use.kinds()[static_cast<std::size_t>(k)];
  const std::string said = ident.known() ? ident.kind() + " (" + ident.source() + ", " +
                                               fixed(100.0 * ident.confidence(), "%.0f") + " % confident)"
                                         : std::string("unknown");
  report.notes.push_back("identified as " + said);

  assume_kind_size(r, said, report);
  G2P_RETURN_IF_ERROR(context.report(Stage::kIdentify, 1.0, ident.kind()));
  r.stages.push_back(clock.finish());
  r.peak_rss_bytes = std::max(r.peak_rss_bytes, r.stages.back().peak_rss_bytes);
  return Status::Ok();
}

std::size_t estimate_run_memory(const PipelineOptions& o, std::size_t triangles) {
  const std::size_t pixels = static_cast<std::size_t>(std::max(0, o.views.num_views)) *
                             static_cast<std::size_t>(std::max(0, o.views.width)) *
                             static_cast<std::size_t>(std::max(0, o.views.height));
  return pixels * 100 + triangles * 1024 + (std::size_t{200} << 20);  // plus the process itself
}

namespace {

// The memory a run may use: the option, else physical memory or the
// address-space limit, whichever is lower.
std::size_t memory_limit(const PipelineOptions& o) {
  if (o.memory_limit_bytes > 0) return o.memory_limit_bytes;
  std::size_t limit =
      static_cast<std::size_t>(::sysconf(_SC_PHYS_PAGES)) * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
    limit = std::min(limit, static_cast<std::size_t>(as.rlim_cur));
  return limit;
}

std::string gib(std::size_t bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f GiB", static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0));
  return b;
}

}  // namespace

Result<PipelineResult> Pipeline::run(Model model, RunContext* context) {
  try {
    return run_unguarded(std::move(model), context);
  } catch (const std::bad_alloc&) {
    return Status::OutOfMemory("the run ran out of memory; lower --resolution or --views, or run with more memory");
  }
}

Result<PipelineResult> Pipeline::run_unguarded(Model model, RunContext* context) {
  const auto start = std::chrono::steady_clock::now();
  RunContext local;
  RunContext& ctx = context != nullptr ? *context : local;
  G2P_RETURN_IF_ERROR(prepare());
  if (model.mesh.num_faces() == 0)
    return Status::InvalidArgument(
        "pipeline: " + (model.info.path.empty() ? std::string("the model") : model.info.path) + " has no triangles");
  const std::size_t need = estimate_run_memory(impl_->options, model.mesh.triangles.size());
  const std::size_t limit = memory_limit(impl_->options);
  if (need > limit)
    return Status::OutOfMemory(
        "the run would need about " + gib(need) + " (" + std::to_string(impl_->options.views.num_views) + " views of " +
        std::to_string(impl_->options.views.width) + " x " + std::to_string(impl_->options.views.height) + " pixels, " +
        std::to_string(model.mesh.num_faces()) + " triangles), more than the " + gib(limit) +
        " it may use; lower --resolution or --views, or raise --memory-limit");
  G2P_RETURN_IF_ERROR(ctx.report(Stage::kRender, 0.0, "starting"));
  PipelineResult r;
  r.model = std::move(model);
  if (impl_->options.anonymize_names) anonymize_names(r.model);
  if (impl_->options.base_color_only) reduce_to_base_color(r.model);
  r.table = impl_->table;
  Status s = impl_->run_stages(r, ctx, Stage::kRender, impl_->options.last_stage);
  if (!s.ok()) {
    const std::string& path = r.model.info.path;
    return path.empty() ? s : s.with_context(path);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

Result<PipelineResult> Pipeline::run_file(const std::string& path, RunContext* context) {
  RunContext local;
  RunContext& ctx = context != nullptr ? *context : local;
  G2P_RETURN_IF_ERROR(prepare());  // bad names fail before a long load
  const auto start = std::chrono::steady_clock::now();
  detail::StageClock clock(Stage::kLoad, "assimp", impl_->options.measure_stage_memory);
  G2P_RETURN_IF_ERROR(ctx.report(Stage::kLoad, 0.0, path));
  Result<Model> model = Status::Internal("not loaded");
  try {
    model = load_model(path, impl_->options.import);
  } catch (const std::bad_alloc&) {
    return Status::OutOfMemory(path + ": ran out of memory while loading it");
  }
  if (!model.ok()) return model.status();
  G2P_RETURN_IF_ERROR(ctx.report(Stage::kLoad, 1.0, std::to_string(model->mesh.num_faces()) + " triangles"));
  const StageReport load = clock.finish();
  Result<PipelineResult> r = run(std::move(*model), &ctx);
  if (!r.ok()) return r;
  r->stages.insert(r->stages.begin(), load);
  r->peak_rss_bytes = std::max(r->peak_rss_bytes, load.peak_rss_bytes);
  r->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

namespace {

// What a resumed run needs of its state before `first`, said in the terms of
// the commands that make it.
Status check_resumable(const PipelineResult& r, Stage first) {
  auto missing = [&](const std::string& what, const char* command) {
    return Status::InvalidArgument("Pipeline::resume at " + std::string(to_string(first)) + ": the state has no " +
                                   what + " (run " + command + " first)");
  };
  if (r.model.mesh.num_faces() == 0) return missing("model", "g2p project");
  if (r.table.size() == 0) return missing("material table", "g2p project");
  if (first == Stage::kRefine && (r.views.empty() || r.projection.graph.num_faces() != r.model.mesh.num_faces()))
    return missing("views and votes", "g2p project");
  if (r.projection.labels.label.size() != static_cast<std::size_t>(r.model.mesh.num_faces()))
    return missing("face labels", "g2p project");
  if (first > Stage::kComplete && r.completion.parts.size() != r.projection.parts.size())
    return missing("closed parts", "g2p complete");
  if (first > Stage::kProperties && r.properties.parts.size() != r.projection.parts.size())
    return missing("properties", "g2p properties");
  return Status::Ok();
}

}  // namespace

Result<PipelineResult> Pipeline::resume(PipelineResult state, Stage first, Stage last, RunContext* context) {
  try {
    const auto start = std::chrono::steady_clock::now();
    RunContext local;
    RunContext& ctx = context != nullptr ? *context : local;
    G2P_RETURN_IF_ERROR(prepare());
    if (first < Stage::kRefine || first > Stage::kExport)
      return Status::InvalidArgument(std::string("Pipeline::resume: the first stage must be refine ... export (got ") +
                                     to_string(first) + "); a run from the model is Pipeline::run");
    if (last < first)
      return Status::InvalidArgument(std::string("Pipeline::resume: the last stage (") + to_string(last) +
                                     ") comes before the first (" + to_string(first) + ")");
    // Corrections go back as far as what they change.
    const Overrides& corrections = impl_->options.overrides;
    if (corrections.changes_labels())
      first = std::min(first, Stage::kComplete);
    else if (!corrections.empty())
      first = std::min(first, Stage::kProperties);
    if (!corrections.object.empty()) {  // what the object is, corrected: its kind weighs the parts
      Result<std::string> kind = kind_from_text(impl_->object_table(), corrections.object, "the overrides' \"object\"");
      if (!kind.ok()) return kind.status();
      const int k = impl_->object_table().find(*kind);
      state.kind = impl_->object_table().kinds()[static_cast<std::size_t>(k)];
      state.identification.candidates.insert(
          state.identification.candidates.begin(),
          KindGuess{*kind, 1.0, "override", "overrides \"object\": '" + corrections.object + "'"});
    }
    G2P_RETURN_IF_ERROR(check_resumable(state, first));
    state.stages.clear();
    state.peak_rss_bytes = 0;
    state.last_stage = static_cast<Stage>(static_cast<int>(first) - 1);
    Status s = impl_->run_stages(state, ctx, first, last);
    if (!s.ok()) return state.model.info.path.empty() ? s : s.with_context(state.model.info.path);
    state.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return state;
  } catch (const std::bad_alloc&) {
    return Status::OutOfMemory("the run ran out of memory while resuming it");
  }
}

Result<PipelineResult> Pipeline::resume(const std::string& folder, Stage first, Stage last, RunContext* context) {
  Result<FolderState> state = read_pipeline_folder(folder, first, impl_->options.import);
  if (!state.ok()) return state.status();
  // What the folder was made with stays: how its model is read and its labels voted.
  PipelineOptions& o = impl_->options;
  const FolderManifest& m = state->manifest;
  o.import.unit_scale = m.import.unit_scale;
  o.import.height_m = m.import.height_m;
  o.import.longest_side_m = m.import.longest_side_m;
  o.import.up_axis = m.import.up_axis;
  o.import.z_up = m.import.z_up;
  o.import.load_textures = m.import.load_textures;
  o.import.strict = m.import.strict;
  o.anonymize_names = m.anonymize_names;
  o.base_color_only = m.base_color_only;
  o.project = m.project;
  Result<PipelineResult> r = resume(std::move(state->result), state->first, last, context);
  if (r.ok()) r->warnings.insert(r->warnings.begin(), state->notes.begin(), state->notes.end());
  return r;
}

}  // namespace g2p
