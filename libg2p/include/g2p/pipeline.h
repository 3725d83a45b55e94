// The whole Gen2Physics method in one call: a mesh in, simulation-ready parts
// out. Pipeline runs the six stages (render, segment, project, refine,
// complete, properties), with the object identified after render (what it is
// sets a normalised mesh's size and checks its mass), and builds the
// simulation asset; every stage's backend
// is chosen by name through its registry or given as an object (a user's own
// Segmenter, say). write_pipeline_output() then writes the output folder
// atomically (docs/pipeline.md lists what it holds).
//
//   g2p::Pipeline pipeline;                       // the offline defaults
//   g2p::Result<g2p::PipelineResult> r = pipeline.run_file("chair.glb");
//   if (r.ok()) g2p::write_pipeline_output("out/chair", *r);
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "g2p/complete.h"
#include "g2p/decompose.h"
#include "g2p/export.h"
#include "g2p/identify.h"
#include "g2p/io.h"
#include "g2p/materials.h"
#include "g2p/model.h"
#include "g2p/overrides.h"
#include "g2p/posterior.h"
#include "g2p/project.h"
#include "g2p/properties.h"
#include "g2p/refine.h"
#include "g2p/registry.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "g2p/status.h"
#include "g2p/visibility.h"

namespace g2p {

// The steps of one run, in order. kLoad only runs in Pipeline::run_file.
enum class Stage {
  kLoad,
  kRender,
  kIdentify,
  kSegment,
  kProject,
  kRefine,
  kComplete,
  kProperties,
  kDecompose,
  kExport
};
constexpr int kNumStages = 10;
G2P_API const char* to_string(Stage stage);  // "load", "render", "identify", ... "decompose", "export"

// ---- Progress and cancellation ------------------------------------------------

struct Progress {
  Stage stage = Stage::kLoad;
  double stage_fraction = 0.0;  // [0, 1] within the stage
  double overall = 0.0;         // [0, 1] over the whole run, weighted by typical stage cost
  std::string message;          // "view 3/11", "closed 12 parts", ...
};

// One object for a run's progress reports and its cooperative cancellation.
// cancel() may be called from any thread (a UI's button, a signal handler);
// the run checks between stages, between views and inside the complete stage
// (between its steps and parts: CompletionInput::progress), and returns
// StatusCode::kCancelled at the next check, having written nothing.
class G2P_API RunContext {
 public:
  using ProgressCallback = std::function<void(const Progress&)>;

  RunContext() = default;
  explicit RunContext(ProgressCallback on_progress) : on_progress_(std::move(on_progress)) {}

  void cancel() { cancelled_.store(true); }
  bool cancelled() const { return cancelled_.load(); }

  // For stages: reports progress (the callback runs on the calling thread)
  // and returns kCancelled once cancel() was called. A callback that throws
  // cancels the run (kCancelled, with the exception's message).
  Status report(Stage stage, double stage_fraction, const std::string& message = {});

 private:
  ProgressCallback on_progress_;
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;  // serialises callbacks when stages report from worker threads
};

// ---- Options ------------------------------------------------------------------

// A backend by registry name plus its KEY=VALUE settings (docs per stage).
struct BackendChoice {
  std::string name;
  BackendSettings settings;
};

struct PipelineOptions {
  ImportOptions import;          // run_file only
  bool anonymize_names = false;  // drop mesh/material/texture names first (as generated meshes have none)
  bool base_color_only = false;  // keep only base colour, metallic/roughness at glTF's 1 (as generators emit)

  // 1. render: 11 views at 512 x 512 (the paper's set-up), full buffers.
  BackendChoice renderer{"embree", {}};
  ViewOptions views;
  RenderOptions render;

  // Identify (after render): what the object is, from the user's words, the
  //    file's names and the views: "auto" (the default), "object", "names",
  //    "detector", "vlm", "none" (identify.h, docs/identify.md).
  BackendChoice identifier{"auto", {}};
  std::string object;  // the user's words for the object ("exercise bike"; g2p run --object); "" = none
  // The run acts on a kind identified with at least `kind_confidence`: a mesh
  // that looks normalised (ImportInfo::looks_normalised), with no size given,
  // gets its typical longest side (unless SizePolicy::kFile), the properties
  // stage uses its structure and hidden mass (unless !kind_properties:
  // estimate_properties_of_kind), and the mass is checked against its range.
  // Below it the identification is reported and nothing else follows from it
  // (the detector alone was right 2 of 2 times above 0.6 and 5 of 33 below it
  // on the validation models, names removed: accuracy.md).
  double kind_confidence = 0.6;  // [0, 1]
  SizePolicy size_policy = SizePolicy::kKind;
  bool kind_properties = true;
  // With a kind the run acts on, the kind decides what the surface cannot
  // show (posterior.h): a class covers no more of the surface than the kind
  // allows it (after refine), and each part's structure, wall and density are
  // chosen against the kind's mass at the object's size (after properties),
  // with a median and 90 % interval in the report. Of an unknown kind, the
  // mass is judged the same way against everyday objects' bulk density (a
  // weak belief: mostly an interval). false: none of these.
  bool kind_posterior = true;
  PosteriorOptions posterior;
  // The kind's materials by role (ObjectKind::materials) as evidence for the
  // classes decided from the image: the network's pixels and the `regions`
  // refiner's regions weigh each class the kind lists 1 and every other
  // `kind_prior`, then renormalise (kind_class_prior, apply_class_prior).
  // 1 = the kind's materials are not used. 0.05 was chosen on validation
  // from {0.5, 0.2, 0.05}: with the kind known and names removed, +6.4 and
  // +7.5 mIoU points; with the kind from the views, -0.1 and -0.2 (accuracy.md).
  double kind_prior = 0.05;  // (0, 1]

  // 2. segment: "hybrid" (the default: `pbr` on per-part materials, the
  //    shipped network where one material covers the whole object with a
  //    baked atlas, as image-to-3D meshes come), "pbr" (weight-free),
  //    "learned", "onnx", "oracle", or a user's (docs/segment.md).
  BackendChoice segmenter{"hybrid", {}};

  // 3. project: votes, flood fill and parts.
  ProjectOptions project;

  // 4. refine (optional): "smooth" (offline default), "vlm", "none". A failure
  //    keeps the projected labels and is reported as a warning.
  BackendChoice refiner{"smooth", {}};

  // 5. complete: "partition" (default), "external"; "alpha-wrap" and "fill" once
  //    the GPL component is registered (g2p::cgal::register_cgal_completers).
  BackendChoice completer{"partition", {}};
  std::string completion_fallback = "partition";  // for parts the completer fails; "" = none
  // Parts whose faces already bound a solid are kept as given, and the
  // completer closes only the others (CompletionOptions::keep_closed_parts).
  bool keep_closed_parts = true;
  // Parts whose volume disagrees with the input's faces are tried again
  // (a closing fitted to their thickness, a shell of it), kept where they
  // agree better (CompletionOptions::resolve_thin_parts).
  bool resolve_thin_parts = true;

  // 6. properties: "table" (default) or "vlm" (falls back to the table per part).
  BackendChoice estimator{"table", {}};

  // Corrections a person made (summary.html, docs/pipeline.md#overrides):
  // classes change after refine, before complete; structure, wall thickness
  // and density replace the estimator's. Part indices refer to the parts a
  // run with the same options makes, so a page's file applies to a rerun of
  // its model. Empty: none.
  Overrides overrides;

  // 7. decompose: each part's collision geometry, convex hulls sized for
  //    engines: "voxel-cut" (default), "hull" (one per part), or a user's.
  BackendChoice decomposer{"voxel-cut", {}};
  DecomposeOptions decompose;

  // Export: the asset's name ("" = the model file's stem, else "object"),
  // MJCF joint choice, and the formats write_pipeline_output writes.
  std::string name;
  ExportOptions export_options;
  std::vector<std::string> formats{"mjcf", "urdf", "sdf", "glb"};

  // Stop after this stage: ablations of the labelling stages (segment,
  // project, refine) need no closed volumes. A result that stops before
  // kExport has no asset and cannot be written as an output folder.
  Stage last_stage = Stage::kExport;  // kRender ... kExport

  // The most memory a run may plan to use, in bytes; 0: this machine's
  // physical memory (or the process's address-space limit, if lower). A run
  // whose views, label maps and mesh would need more (estimate_run_memory)
  // is refused before any work with kOutOfMemory, and an allocation that
  // fails anyway ends the run with kOutOfMemory, never an exception.
  std::size_t memory_limit_bytes = 0;

  // Measure each stage's peak resident memory by resetting the process's
  // high-water mark (Linux /proc/self/clear_refs) before it. Off: the
  // process's peak so far is reported instead.
  bool measure_stage_memory = true;
};

// The settings one backend takes: the stage's registry name, and each
// setting with a new instance's default (settings.h).
struct BackendSettingsInfo {
  Stage stage = Stage::kSegment;  // kIdentify, kSegment, kRefine, kComplete, kProperties or kDecompose
  std::string backend;
  std::vector<SettingInfo> settings;
};

// The backends called `name` in any stage ("vlm" refines, estimates and
// identifies), or in one ("refine:vlm"), with their settings; "all" lists
// every backend of every stage. NotFound names the known backends.
G2P_API Result<std::vector<BackendSettingsInfo>> describe_backend_settings(const std::string& name);

// ---- Results ------------------------------------------------------------------

struct StageReport {
  Stage stage = Stage::kLoad;
  // The backend's registry name, "custom" for a given object; load, project
  // and export have one implementation each: "assimp", "vote", "asset".
  std::string backend;
  double seconds = 0.0;            // wall time
  std::size_t peak_rss_bytes = 0;  // peak resident memory during the stage (see measure_stage_memory)
  bool ok = true;                  // false: an optional stage failed and the run went on without it
  std::string error;               // why, when !ok
  std::vector<std::string> notes;
};

struct G2P_API PipelineResult {
  Model model;
  MaterialTable table;
  std::vector<View> views;
  Identification identification;      // what the object is (unknown when the identifier could not tell)
  ObjectKind kind;                    // its entry in the object table; name "" when unknown
  double size_assumed_m = 0.0;        // > 0: the kind's longest side the run gave a normalised mesh, metres
  std::vector<LabelMap> label_maps;   // per view, from the segmenter
  Projection projection;              // after refinement when it ran
  std::vector<int> projected_labels;  // per face, before refinement (for ablations)
  RefineResult refinement;            // empty when the refiner was "none" or returned an error; when it
                                      // fell back (fell_back) its labels are the projected ones
  Completion completion;
  PropertiesReport properties;
  std::vector<ConvexDecomposition> collision;  // per part (same order as completion.parts)
  SimulationAsset asset;
  std::vector<StageReport> stages;             // in run order
  std::vector<std::string> warnings;           // degraded optional stages, in words
  std::vector<std::string> overrides_applied;  // what PipelineOptions::overrides changed, one line per entry
  Overrides overrides;  // the overrides applied, as face selections (as_face_selections; overrides.json)
  std::vector<std::uint8_t> image_decided;  // per face, 1 where the segmenter decided from the image alone
  double kind_scale = 1.0;                  // the factor that gave the mesh its kind's size (size_assumed_m)
  // Parts whose class the kind's share changed (fit_classes_to_kind), in words.
  std::vector<std::string> kind_class_changes;
  Stage last_stage = Stage::kLoad;  // the last stage the result holds
  double seconds = 0.0;             // whole run
  std::size_t peak_rss_bytes = 0;   // largest stage peak

  const StageReport* stage(Stage s) const;  // null if it did not run
};

// What a run of `options` on a mesh of `triangles` will hold at its peak, in
// bytes, roughly: about 100 bytes per pixel of every view (its buffers and
// its label map with class probabilities) and 1 KiB per triangle (the mesh,
// face graph, votes and closed volumes).
G2P_API std::size_t estimate_run_memory(const PipelineOptions& options, std::size_t triangles);

// ---- The pipeline -------------------------------------------------------------

class G2P_API Pipeline {
 public:
  explicit Pipeline(PipelineOptions options = {});
  ~Pipeline();
  Pipeline(Pipeline&&) noexcept;
  Pipeline& operator=(Pipeline&&) noexcept;

  const PipelineOptions& options() const;
  PipelineOptions& options();  // changes apply to the next run

  // Backend objects replace the named ones; null goes back to the name.
  // Shared, so a caller (or Python) may keep its own handle.
  void set_renderer(std::shared_ptr<Renderer> renderer);
  void set_identifier(std::shared_ptr<Identifier> identifier);
  void set_object_table(ObjectTable table);  // default: ObjectTable::shipped()
  void set_segmenter(std::shared_ptr<Segmenter> segmenter);
  void set_refiner(std::shared_ptr<Refiner> refiner);
  void set_completer(std::shared_ptr<Completer> completer);
  void set_estimator(std::shared_ptr<PropertyEstimator> estimator);
  void set_decomposer(std::shared_ptr<Decomposer> decomposer);
  void set_material_table(MaterialTable table);  // default: MaterialTable::paper_default()
  const MaterialTable& material_table() const;   // the one runs use (overrides name its classes)

  // Creates and configures every named backend now: unknown names or settings
  // fail here, before any work. run() calls it; calling it first is optional.
  Status prepare();

  // Runs the stages on a loaded model (moved into the result). Deterministic:
  // the same model and options give the same labels, parts and masses.
  Result<PipelineResult> run(Model model, RunContext* context = nullptr);
  // Loads the file with options().import, then runs.
  Result<PipelineResult> run_file(const std::string& path, RunContext* context = nullptr);

  // Runs the stages from `first` to `last` on a state that holds everything
  // before `first` (read_pipeline_folder, labelled_from_truth in folder.h):
  // the same code as run(), so a folder advanced stage by stage holds what one
  // run() to `last` holds. `first` is kRefine ... kExport; corrections
  // (options().overrides, after the state's own PipelineResult::overrides)
  // that change classes resume at complete at the latest, ones that change
  // properties or what the object is at properties.
  Result<PipelineResult> resume(PipelineResult state, Stage first, Stage last, RunContext* context = nullptr);
  // Reads `folder` (read_pipeline_folder) and resumes it; its notes (a stage
  // run again because the folder lacks its input) join the result's warnings.
  Result<PipelineResult> resume(const std::string& folder, Stage first, Stage last, RunContext* context = nullptr);

 private:
  Result<PipelineResult> run_unguarded(Model model, RunContext* context);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ---- The output folder --------------------------------------------------------

struct OutputOptions {
  std::string written_by = "libg2p";  // the command or program, recorded in manifest.json
  bool overwrite = false;             // replace an existing folder (only once the new one is complete)
  bool intermediates = false;         // also every view's buffers, per-view probabilities, votes and part patches
  std::vector<std::string> mesh_formats{"obj"};  // the closed parts' formats in completed/: obj, ply, stl
  // The model being run ("": not checked). An existing folder that holds it
  // is never replaced, with or without `overwrite` (write_pipeline_output
  // fills it from the result).
  std::string input_path;
};

// Writes the run into `dir`, as far as it went (PipelineResult::last_stage,
// render at least): manifest.json (folder.h), views/ (renders, face IDs,
// contact sheet), segmented/ and projected/ (label maps, contact sheets),
// faces.csv, labelled.ply, parts.json, refine.json; after complete
// completed/ (closed parts; for a whole run only with intermediates); after
// properties report.json; after export the simulation asset (NAME.xml,
// NAME.urdf, NAME.sdf, NAME.glb, meshes/), run.json and summary.html; and
// overrides.json when corrections were applied. Everything is written to a
// temporary folder beside `dir` and renamed into place at the end: `dir` never
// holds a half-written run or a file of an earlier one, and an existing `dir`
// is only replaced when output.overwrite is set.
G2P_API Status write_pipeline_output(const std::string& dir, const PipelineResult& result,
                                     const PipelineOptions& options = {}, const OutputOptions& output = {});

// Whether write_pipeline_output could write `dir`, checked before a run so
// that a bad folder fails at once, not after the work: `dir` must not exist,
// unless output.overwrite, and then it must be a folder that is empty or
// holds a g2p output (run.json, report.json or project.json), that holds
// neither output.input_path nor the working directory; and the nearest
// existing folder above it must be writable. The message names the folder.
G2P_API Status check_output_folder(const std::string& dir, const OutputOptions& output = {});

// The machine-readable summary (run.json, `g2p run --json`): stages with
// time and memory, parts with class, mass and volume, totals, warnings.
G2P_API std::string pipeline_summary_json(const PipelineResult& result, const PipelineOptions& options = {});

// The same for a terminal, as far as the result goes, each line ending in a
// newline: what the object was identified as, one line per stage (backend,
// seconds, peak MiB), per part its class, faces and area, closed volume,
// structure, density and mass, and the object's mass and centre of mass.
G2P_API std::string pipeline_summary_text(const PipelineResult& result);

// A one-page HTML summary for a person (docs/pipeline.md#summaryhtml): a
// banner for what needs checking, an interactive 3D view (WebGL; the geometry,
// at most 200,000 triangles of it, and the viewer script are in the page, about
// 560 KB plus 30 to 40 bytes a drawn triangle), the parts and masses, every view with
// its labels, the stages in plain words. Images are referenced relative to the
// output folder; nothing is fetched from a network.
G2P_API std::string summary_html(const PipelineResult& result, const PipelineOptions& options = {});

}  // namespace g2p
