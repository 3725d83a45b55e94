// The pipeline: options, progress and cancellation, runs with the GIL
// released, and the result as numpy arrays and dicts.
#include <mutex>
#include <optional>
#include <stdexcept>

#include "bindings.h"
#include "g2p/options_file.h"

namespace g2p::python {

namespace {

// A RunContext for Python. The C++ context calls back on the run's thread;
// the callback takes the GIL, calls the user's progress function, and
// cancels the run when it returns False or raises (the exception is kept and
// re-raised when the run returns). It also checks for signals, so Ctrl-C
// cancels a run at its next progress report.
class PyRunContext {
 public:
  explicit PyRunContext(py::object progress) : state_(std::make_unique<State>()) {
    if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
      throw py::type_error("progress must be callable (it receives a g2p.Progress)");
    state_->progress = std::move(progress);
    State* state = state_.get();
    context_ = std::make_unique<RunContext>([state](const Progress& p) { state->on_progress(p); });
    state_->context = context_.get();
  }

  RunContext& context() { return *context_; }
  void cancel() { context_->cancel(); }
  bool cancelled() const { return context_->cancelled(); }
  bool has_progress() const { return !state_->progress.is_none(); }

  // Re-raises what the progress callback raised during the last run, if anything.
  void rethrow_callback_error() {
    if (!state_->error) return;
    py::object error = std::move(state_->error);
    state_->error = py::object();
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    throw py::error_already_set();
  }

 private:
  struct State {
    py::object progress;  // None or callable(g2p.Progress) -> bool | None
    py::object error;     // the exception the callback raised (with its traceback)
    RunContext* context = nullptr;

    void on_progress(const Progress& p) {
      py::gil_scoped_acquire gil;
      if (error) return;
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (progress.is_none()) return;
        py::object keep_going = progress(p);
        if (py::isinstance<py::bool_>(keep_going) && !keep_going.cast<bool>()) context->cancel();
      } catch (py::error_already_set& e) {
        error = e.value();
        if (e.trace()) PyException_SetTraceback(error.ptr(), e.trace().ptr());
        context->cancel();
      }
    }
  };
  std::unique_ptr<State> state_;  // before context_: the callback points into it
  std::unique_ptr<RunContext> context_;
};

// A run's result together with the options it ran with, so that
// write_output() and summary_json() need not be given them again.
struct PyPipelineResult : PipelineResult {
  PipelineOptions options;
};

// The pipeline with a lock: a second run (or a backend swap) from another
// Python thread while one runs without the GIL is refused, not raced.
struct PyPipeline {
  Pipeline pipeline;
  std::mutex busy;

  std::unique_lock<std::mutex> lock(const char* what) {
    std::unique_lock<std::mutex> l(busy, std::try_to_lock);
    if (!l)
      throw std::runtime_error(std::string("g2p.Pipeline.") + what + ": the pipeline is running in another thread");
    return l;
  }
};

py::object run_pipeline(PyPipeline& p, const std::function<Result<PipelineResult>(RunContext*)>& run,
                        const py::object& progress, const py::object& context) {
  std::unique_ptr<PyRunContext> local;
  PyRunContext* ctx = nullptr;
  if (context.is_none()) {
    local = std::make_unique<PyRunContext>(progress);
    ctx = local.get();
  } else {
    if (!progress.is_none()) throw py::type_error("give the progress callback to g2p.RunContext(progress=...)");
    ctx = context.cast<PyRunContext*>();
  }
  auto lock = p.lock("run");
  PipelineOptions options = p.pipeline.options();
  std::optional<Result<PipelineResult>> result;
  {
    py::gil_scoped_release release;
    result.emplace(run(&ctx->context()));
  }
  ctx->rethrow_callback_error();
  if (!result->ok()) throw StatusError(result->status());
  auto out = std::make_unique<PyPipelineResult>();
  static_cast<PipelineResult&>(*out) = std::move(**result);
  out->options = std::move(options);
  return py::cast(std::move(out));
}

// References into `parent` (no copy of views and label maps, which are large).
template <typename T>
py::list reference_list(const std::vector<T>& items, py::handle parent) {
  py::list list;
  for (const T& item : items) list.append(py::cast(&item, py::return_value_policy::reference_internal, parent));
  return list;
}

py::object class_name(const MaterialTable& table, int label) {
  return table.valid_label(label) ? py::object(py::str(table[label].name)) : py::object(py::none());
}

py::dict stage_dict(const StageReport& s) {
  py::dict d;
  d["stage"] = to_string(s.stage);
  d["backend"] = s.backend;
  d["seconds"] = s.seconds;
  d["peak_rss_bytes"] = s.peak_rss_bytes;
  d["ok"] = s.ok;
  d["error"] = s.error;
  d["notes"] = s.notes;
  return d;
}

py::list parts_list(const PipelineResult& r) {
  py::list parts;
  for (std::size_t i = 0; i < r.projection.parts.size(); ++i) {
    const Part& p = r.projection.parts[i];
    py::dict d;
    d["index"] = i;
    d["label"] = p.label;
    d["class"] = class_name(r.table, p.label);
    d["faces"] = vector_to_numpy(p.faces);
    d["area_m2"] = p.area_m2;
    parts.append(d);
  }
  return parts;
}

py::list properties_list(const PipelineResult& r) {
  py::list out;
  for (const PartReport& pr : r.properties.parts) {
    const PartProperties& p = pr.properties;
    py::dict d;
    d["part"] = pr.part;
    d["label"] = p.label;
    d["class"] = class_name(r.table, p.label);
    d["density_kg_m3"] = p.density_kg_m3;
    d["density_range_kg_m3"] = py::make_tuple(p.density_min_kg_m3, p.density_max_kg_m3);
    d["structure"] = to_string(p.structure);
    d["wall_thickness_m"] = p.wall_thickness_m;
    d["double_walled"] = p.double_walled;
    d["friction_static"] = p.friction_static;
    d["friction_dynamic"] = p.friction_dynamic;
    d["restitution"] = p.restitution;
    d["mass_kg"] = pr.mass.mass_kg;
    d["mass_range_kg"] = py::make_tuple(pr.mass_min_kg, pr.mass_max_kg);
    if (pr.mass_median_kg > 0)  // the kind's mass posterior: median and 90 % interval
      d["mass_interval_kg"] = py::make_tuple(pr.mass_p05_kg, pr.mass_median_kg, pr.mass_p95_kg);
    d["volume_m3"] = pr.mass.volume_m3 - pr.contents.volume_m3;
    d["contents_mass_kg"] = pr.contents.mass_kg;  // 0 when empty
    d["contents_fill"] = pr.contents.mass_kg > 0 ? p.contents_fill : 0.0;
    d["contents_density_kg_m3"] = p.contents_density_kg_m3;
    d["area_m2"] = pr.mass.area_m2;
    d["center_of_mass"] = py::cast(pr.mass.center_of_mass);
    d["inertia"] = py::cast(pr.mass.inertia);
    d["completed_ok"] = pr.completed_ok;
    d["sources"] = py::dict(
        py::arg("density") = to_string(p.density_source), py::arg("structure") = to_string(p.structure_source),
        py::arg("thickness") = to_string(p.thickness_source), py::arg("contact") = to_string(p.contact_source));
    d["notes"] = p.notes;
    out.append(d);
  }
  return out;
}

py::object json_loads(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

const PipelineOptions& options_or(const PyPipelineResult& r, const PipelineOptions* options) {
  return options ? *options : r.options;
}

}  // namespace

void bind_pipeline(py::module_& m) {
  py::enum_<Stage>(m, "Stage")
      .value("LOAD", Stage::kLoad)
      .value("RENDER", Stage::kRender)
      .value("IDENTIFY", Stage::kIdentify)
      .value("SEGMENT", Stage::kSegment)
      .value("PROJECT", Stage::kProject)
      .value("REFINE", Stage::kRefine)
      .value("COMPLETE", Stage::kComplete)
      .value("PROPERTIES", Stage::kProperties)
      .value("DECOMPOSE", Stage::kDecompose)
      .value("EXPORT", Stage::kExport)
      .def("__str__", [](Stage s) { return to_string(s); });

  py::class_<Progress>(m, "Progress", "One progress report of a run.")
      .def_readonly("stage", &Progress::stage)
      .def_property_readonly("stage_name", [](const Progress& p) { return to_string(p.stage); })
      .def_readonly("stage_fraction", &Progress::stage_fraction, "[0, 1] within the stage")
      .def_readonly("overall", &Progress::overall, "[0, 1] over the whole run")
      .def_readonly("message", &Progress::message)
      .def("__repr__", [](const Progress& p) {
        return std::string("<g2p.Progress ") + to_string(p.stage) + " " + std::to_string(p.overall) + " '" + p.message +
               "'>";
      });

  py::class_<PyRunContext>(
      m, "RunContext",
      "Progress and cancellation of one run. progress(p: g2p.Progress) is called on the run's thread with the GIL "
      "held; returning False cancels the run (g2p.Cancelled), raising cancels it and the exception is re-raised "
      "when the run returns. cancel() may be called from any thread. A cancelled context stays cancelled: use a "
      "new one per run.")
      .def(py::init<py::object>(), py::arg("progress") = py::none())
      .def("cancel", &PyRunContext::cancel)
      .def_property_readonly("cancelled", &PyRunContext::cancelled);

  // ---- Options ----
  py::class_<BackendChoice>(m, "BackendChoice", "A backend by registry name plus its KEY=VALUE settings.")
      .def(py::init([](std::string name, const py::object& settings, const py::kwargs& kwargs) {
             return BackendChoice{std::move(name), settings_from_python(settings, kwargs)};
           }),
           py::arg("name"), py::arg("settings") = py::none(),
           "BackendChoice('hybrid', colour=False, share=0.5): settings as a dict or keywords, checked by "
           "Pipeline.prepare (g2p.backend_settings('hybrid') lists them)")
      .def_readwrite("name", &BackendChoice::name)
      .def_readwrite("settings", &BackendChoice::settings, "edited in place: choice.settings['key'] = 'value'")
      .def("__repr__", [](const BackendChoice& c) { return "<g2p.BackendChoice '" + c.name + "'>"; });
  // `options.refiner = "none"` for a backend without settings.
  py::implicitly_convertible<py::str, BackendChoice>();

  py::class_<ExportOptions>(m, "ExportOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<ExportOptions>(kw); }))
      .def_readwrite("free_joint", &ExportOptions::free_joint)
      .def_readwrite("use_static_friction", &ExportOptions::use_static_friction)
      .def_readwrite("scale_contacts", &ExportOptions::scale_contacts)
      .def_readwrite("contact_sink", &ExportOptions::contact_sink)
      .def_readwrite("timestep_s", &ExportOptions::timestep_s);

  py::class_<Overrides>(m, "Overrides",
                        "A person's corrections (summary.html's 3D view, docs/pipeline.md#overrides): classes, "
                        "solid/hollow, wall thickness, density and contents per part or face. Read them with "
                        "g2p.read_overrides(path) or g2p.parse_overrides(text); give them to "
                        "PipelineOptions(overrides=...).")
      .def(py::init<>())
      .def("__len__", [](const Overrides& o) { return o.entries.size(); })
      .def_property_readonly("changes_classes", &Overrides::changes_labels)
      .def_property_readonly("changes_properties", &Overrides::changes_properties)
      .def_readwrite("model", &Overrides::model)
      .def_readwrite("faces_total", &Overrides::faces_total, "the input's face count, checked when >= 0")
      .def(
          "to_json", [](const Overrides& o, const MaterialTable& table) { return overrides_json(o, table); },
          py::arg("table") = MaterialTable::paper_default(), "The file's JSON text.");
  m.def(
      "read_overrides",
      [](const std::string& path, const MaterialTable& table) { return unwrap(read_overrides(path, table)); },
      py::arg("path"), py::arg("table") = MaterialTable::paper_default(),
      "Reads an overrides file; a bad entry raises g2p.InvalidArgumentError naming it.");
  m.def(
      "parse_overrides",
      [](const std::string& text, const MaterialTable& table, const std::string& origin) {
        return unwrap(parse_overrides(text, table, origin));
      },
      py::arg("text"), py::arg("table") = MaterialTable::paper_default(), py::arg("origin") = "overrides");

  py::class_<PipelineOptions>(
      m, "PipelineOptions",
      "Everything a run needs; nested structs are edited in place (options.views.num_views = 6). Keyword "
      "construction: g2p.PipelineOptions(refiner='none', formats=['mjcf']).")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<PipelineOptions>(kw); }))
      .def_readwrite("import_options", &PipelineOptions::import, "g2p.ImportOptions for run_file")
      .def_readwrite("anonymize_names", &PipelineOptions::anonymize_names)
      .def_readwrite("base_color_only", &PipelineOptions::base_color_only)
      .def_readwrite("renderer", &PipelineOptions::renderer)
      .def_readwrite("views", &PipelineOptions::views)
      .def_readwrite("render", &PipelineOptions::render)
      .def_readwrite("identifier", &PipelineOptions::identifier,
                     "identify backend: auto (default), object, names, detector, classifier, vlm, none")
      .def_readwrite("object", &PipelineOptions::object, "the object in your words ('exercise bike'); '' = none")
      .def_property(
          "size_from", [](const PipelineOptions& o) { return std::string(to_string(o.size_policy)); },
          [](PipelineOptions& o, const std::string& v) {
            Result<SizePolicy> p = parse_size_policy(v);
            if (!p.ok()) throw py::value_error(p.status().message());
            o.size_policy = *p;
          },
          "'kind' (a normalised mesh takes its identified kind's typical size) or 'file'")
      .def_readwrite("kind_properties", &PipelineOptions::kind_properties,
                     "use a known kind's structure and hidden mass in the properties stage")
      .def_readwrite("kind_posterior", &PipelineOptions::kind_posterior,
                     "with a known kind, limit classes to the kind's share of the surface and choose each part's "
                     "structure against the kind's mass; of an unknown kind, against everyday objects' bulk density "
                     "(g2p run --kind-mass; docs/properties.md)")
      .def_readwrite("kind_confidence", &PipelineOptions::kind_confidence,
                     "the least identification confidence for which the run acts on the kind (size, structure, "
                     "hidden mass, mass check)")
      .def_readwrite("kind_prior", &PipelineOptions::kind_prior,
                     "weight, against 1, of the classes a confident kind does not list, on the classes read from the "
                     "image; 1 = the kind's materials are not used")
      .def_readwrite("segmenter", &PipelineOptions::segmenter)
      .def_readwrite("project", &PipelineOptions::project)
      .def_readwrite("refiner", &PipelineOptions::refiner)
      .def_readwrite("completer", &PipelineOptions::completer)
      .def_readwrite("completion_fallback", &PipelineOptions::completion_fallback, "'' = none")
      .def_readwrite("keep_closed_parts", &PipelineOptions::keep_closed_parts,
                     "parts whose faces already bound a solid are kept as given")
      .def_readwrite("resolve_thin_parts", &PipelineOptions::resolve_thin_parts,
                     "parts whose volume disagrees with the input's faces are tried again (closing, shell)")
      .def_readwrite("estimator", &PipelineOptions::estimator)
      .def_readwrite("memory_limit_bytes", &PipelineOptions::memory_limit_bytes,
                     "refuse runs needing more; 0 = the machine's memory")
      .def_readwrite("decomposer", &PipelineOptions::decomposer, "decompose backend: voxel-cut (default), hull")
      .def_readwrite("decompose", &PipelineOptions::decompose, "g2p.DecomposeOptions")
      .def_readwrite("name", &PipelineOptions::name, "the asset's name ('' = the file's stem)")
      .def_readwrite("export_options", &PipelineOptions::export_options)
      .def_readwrite("formats", &PipelineOptions::formats,
                     "a list copy: assign a new list (options.formats = ['mjcf']) to change it")
      .def_readwrite("overrides", &PipelineOptions::overrides, "g2p.Overrides: corrections to apply")
      .def_readwrite("last_stage", &PipelineOptions::last_stage)
      .def_readwrite("measure_stage_memory", &PipelineOptions::measure_stage_memory);

  // ---- Options files (g2p/options_file.h) ----
  auto pair = [](RunOptions r) { return py::make_tuple(std::move(r.pipeline), std::move(r.materials)); };
  auto base = [](const py::object& options, const py::object& materials) {
    RunOptions r;
    if (!options.is_none()) r.pipeline = options.cast<PipelineOptions>();
    if (!materials.is_none()) r.materials = materials.cast<MaterialTable>();
    return r;
  };
  m.def(
      "options_file_json",
      [base](const py::object& options, const py::object& materials) {
        return options_file_json(base(options, materials));
      },
      py::arg("options") = py::none(), py::arg("materials") = py::none(),
      "An options file's text (what `g2p run --options` reads) for g2p.PipelineOptions and a g2p.MaterialTable.");
  m.def(
      "parse_options_file",
      [pair, base](const std::string& text, const py::object& options, const py::object& materials) {
        return pair(unwrap(parse_options_file(text, "options", base(options, materials))));
      },
      py::arg("text"), py::arg("options") = py::none(), py::arg("materials") = py::none(),
      "(PipelineOptions, MaterialTable) from an options file's text: the keys it gives over options and materials "
      "(default: the library's). An unknown key or a bad value raises naming its key path.");
  m.def(
      "read_options_file",
      [pair, base](const py::object& path, const py::object& options, const py::object& materials) {
        const std::string file = py::str(py::module_::import("os").attr("fspath")(path));
        return pair(unwrap(read_options_file(file, base(options, materials))));
      },
      py::arg("path"), py::arg("options") = py::none(), py::arg("materials") = py::none(),
      "parse_options_file on a file (an output folder's options.json is one).");

  // ---- Result ----
  py::class_<PyPipelineResult>(
      m, "PipelineResult",
      "One run's result. Per-face arrays are numpy copies; views and label_maps are references into the result.")
      .def_readonly("model", &PipelineResult::model)
      .def_readonly("table", &PipelineResult::table)
      .def_readonly("options", &PyPipelineResult::options, "the options the run used")
      .def(
          "summary", [](const PyPipelineResult& r) { return pipeline_summary_text(r); },
          "what `g2p run` prints: the object, each stage, each part, the mass")
      .def_property_readonly("views",
                             [](py::object self) { return reference_list(self.cast<PyPipelineResult&>().views, self); })
      .def_property_readonly(
          "label_maps", [](py::object self) { return reference_list(self.cast<PyPipelineResult&>().label_maps, self); })
      .def_readonly("projection", &PipelineResult::projection)
      .def_property_readonly(
          "face_labels", [](const PyPipelineResult& r) { return vector_to_numpy(r.projection.labels.label); },
          "(M,) int32 class per face after refinement")
      .def_property_readonly("face_confidence",
                             [](const PyPipelineResult& r) { return vector_to_numpy(r.projection.labels.confidence); })
      .def_property_readonly(
          "projected_labels", [](const PyPipelineResult& r) { return vector_to_numpy(r.projected_labels); },
          "(M,) int32 class per face before refinement")
      .def_property_readonly("face_part",
                             [](const PyPipelineResult& r) { return vector_to_numpy(r.projection.face_part); })
      .def_property_readonly(
          "parts", [](const PyPipelineResult& r) { return parts_list(r); },
          "list of dicts: index, label, class, faces (int32), area_m2")
      .def_readonly("refinement", &PipelineResult::refinement)
      .def_readonly("completion", &PipelineResult::completion)
      .def_readonly("collision", &PipelineResult::collision, "per part, its g2p.ConvexDecomposition")
      .def_readonly("properties_report", &PipelineResult::properties)
      .def_property_readonly(
          "properties", [](const PyPipelineResult& r) { return properties_list(r); },
          "list of dicts per part: density_kg_m3, structure, wall_thickness_m, mass_kg, center_of_mass, inertia, ...")
      .def_property_readonly("mass_kg", [](const PyPipelineResult& r) { return r.properties.object.mass_kg; })
      .def_property_readonly(
          "mass_range_kg",
          [](const PyPipelineResult& r) { return py::make_tuple(r.properties.mass_min_kg, r.properties.mass_max_kg); })
      .def_property_readonly(
          "center_of_mass",
          [](const PyPipelineResult& r) { return Eigen::Vector3d(r.properties.object.center_of_mass); })
      .def_property_readonly(
          "inertia", [](const PyPipelineResult& r) { return Eigen::Matrix3d(r.properties.object.inertia); },
          "(3, 3) kg m^2 about the centre of mass")
      .def_property_readonly("asset_name", [](const PyPipelineResult& r) { return r.asset.name; })
      .def_property_readonly(
          "identification",
          [](const PyPipelineResult& r) {
            return json_loads(identification_json(r.identification, ObjectTable::shipped(), r.size_assumed_m));
          },
          "what the object was identified as: a dict (kind, confidence, source, candidates, ...)")
      .def_property_readonly(
          "kind", [](const PyPipelineResult& r) { return r.identification.kind(); }, "the object's kind, or 'unknown'")
      .def_readonly("size_assumed_m", &PipelineResult::size_assumed_m,
                    "> 0: the longest side the run gave a normalised mesh from its kind")
      .def_property_readonly("stages",
                             [](const PyPipelineResult& r) {
                               py::list l;
                               for (const StageReport& s : r.stages) l.append(stage_dict(s));
                               return l;
                             })
      .def(
          "stage",
          [](const PyPipelineResult& r, Stage s) -> py::object {
            const StageReport* report = r.stage(s);
            return report ? py::object(stage_dict(*report)) : py::object(py::none());
          },
          "The stage's report as a dict, or None if it did not run.")
      .def_readonly("warnings", &PipelineResult::warnings)
      .def_readonly("overrides_applied", &PipelineResult::overrides_applied,
                    "what PipelineOptions.overrides changed, one line per entry")
      .def_readonly("seconds", &PipelineResult::seconds)
      .def_readonly("peak_rss_bytes", &PipelineResult::peak_rss_bytes)
      .def(
          "summary_json",
          [](const PyPipelineResult& r, const PipelineOptions* options) {
            return json_loads(pipeline_summary_json(r, options_or(r, options)));
          },
          py::arg("options") = static_cast<const PipelineOptions*>(nullptr), "run.json as a dict")
      .def(
          "summary_html",
          [](const PyPipelineResult& r, const PipelineOptions* options) {
            return summary_html(r, options_or(r, options));
          },
          py::arg("options") = static_cast<const PipelineOptions*>(nullptr))
      .def(
          "report_json", [](const PyPipelineResult& r) { return json_loads(report_json(r.properties, r.table)); },
          "report.json (docs/report-schema.md) as a dict");

  // ---- Pipeline ----
  py::class_<PyPipeline>(m, "Pipeline",
                         "The six stages in one call. Backends are chosen by name in the options or given as objects "
                         "(set_segmenter(MySegmenter()), Python subclasses included); None goes back to the name.")
      .def(py::init([](const py::object& options, const py::kwargs& kwargs) {
             if (!options.is_none() && kwargs.size() > 0)
               throw py::type_error("Pipeline: give either options or keyword options, not both");
             auto p = std::make_unique<PyPipeline>();
             p->pipeline.options() =
                 options.is_none() ? from_kwargs<PipelineOptions>(kwargs) : options.cast<PipelineOptions>();
             return p;
           }),
           py::arg("options") = py::none())
      .def_property(
          "options", [](PyPipeline& p) { return &p.pipeline.options(); },
          [](PyPipeline& p, const PipelineOptions& o) {
            auto lock = p.lock("options");
            p.pipeline.options() = o;
          },
          py::return_value_policy::reference_internal, "edited in place; changes apply to the next run")
      .def(
          "set_renderer",
          [](PyPipeline& p, py::object r) {
            auto lock = p.lock("set_renderer");
            p.pipeline.set_renderer(hold_python_object<Renderer>(std::move(r)));
          },
          py::arg("renderer"))
      .def(
          "set_segmenter",
          [](PyPipeline& p, py::object s) {
            auto lock = p.lock("set_segmenter");
            p.pipeline.set_segmenter(hold_python_object<Segmenter>(std::move(s)));
          },
          py::arg("segmenter"))
      .def(
          "set_refiner",
          [](PyPipeline& p, py::object r) {
            auto lock = p.lock("set_refiner");
            p.pipeline.set_refiner(hold_python_object<Refiner>(std::move(r)));
          },
          py::arg("refiner"))
      .def(
          "set_completer",
          [](PyPipeline& p, py::object c) {
            auto lock = p.lock("set_completer");
            p.pipeline.set_completer(hold_python_object<Completer>(std::move(c)));
          },
          py::arg("completer"))
      .def(
          "set_estimator",
          [](PyPipeline& p, py::object e) {
            auto lock = p.lock("set_estimator");
            p.pipeline.set_estimator(hold_python_object<PropertyEstimator>(std::move(e)));
          },
          py::arg("estimator"))
      .def(
          "set_decomposer",
          [](PyPipeline& p, py::object d) {
            auto lock = p.lock("set_decomposer");
            p.pipeline.set_decomposer(hold_python_object<Decomposer>(std::move(d)));
          },
          py::arg("decomposer"))
      .def(
          "set_material_table",
          [](PyPipeline& p, MaterialTable table) {
            auto lock = p.lock("set_material_table");
            p.pipeline.set_material_table(std::move(table));
          },
          py::arg("table"))
      .def(
          "prepare",
          [](PyPipeline& p) {
            auto lock = p.lock("prepare");
            py::gil_scoped_release release;
            throw_if_error(p.pipeline.prepare());
          },
          "Creates and configures every named backend now; unknown names or settings raise here.")
      .def(
          "run",
          [](PyPipeline& p, Model model, const py::object& progress, const py::object& context) {
            return run_pipeline(
                p, [&](RunContext* ctx) { return p.pipeline.run(std::move(model), ctx); }, progress, context);
          },
          py::arg("model"), py::arg("progress") = py::none(), py::arg("context") = py::none(),
          "Runs the stages on a copy of the model. The GIL is released meanwhile.")
      .def(
          "run_file",
          [](PyPipeline& p, const std::string& path, const py::object& progress, const py::object& context) {
            return run_pipeline(
                p, [&](RunContext* ctx) { return p.pipeline.run_file(path, ctx); }, progress, context);
          },
          py::arg("path"), py::arg("progress") = py::none(), py::arg("context") = py::none(),
          "Loads the file with options.import_options, then runs.")
      .def(
          "resume",
          [](PyPipeline& p, const std::string& folder, Stage first, Stage last, const py::object& progress,
             const py::object& context) {
            return run_pipeline(
                p, [&](RunContext* ctx) { return p.pipeline.resume(folder, first, last, ctx); }, progress, context);
          },
          py::arg("folder"), py::arg("first"), py::arg("last") = Stage::kExport, py::arg("progress") = py::none(),
          py::arg("context") = py::none(),
          "Reads an output folder (write_output's) and runs the stages from first to last on it, as g2p refine, "
          "complete, properties and export do; the result holds the folder's earlier stages.")
      .def(
          "resume",
          [](PyPipeline& p, const PyPipelineResult& result, Stage first, Stage last, const py::object& progress,
             const py::object& context) {
            PipelineResult state = result;  // the earlier result stays as it was
            return run_pipeline(
                p, [&](RunContext* ctx) { return p.pipeline.resume(std::move(state), first, last, ctx); }, progress,
                context);
          },
          py::arg("result"), py::arg("first"), py::arg("last") = Stage::kExport, py::arg("progress") = py::none(),
          py::arg("context") = py::none(),
          "Runs the stages from first to last on a copy of an earlier run's result, without files: corrections in "
          "options.overrides go back as far as what they change (classes: complete; properties or the object: "
          "properties), after the result's own.");

  m.def(
      "write_output",
      [](const std::string& dir, const PyPipelineResult& result, const PipelineOptions* options, bool overwrite,
         bool intermediates) {
        const PipelineOptions& o = options_or(result, options);
        OutputOptions output;
        output.written_by = "g2p (Python)";
        output.overwrite = overwrite;
        output.intermediates = intermediates;
        py::gil_scoped_release release;
        throw_if_error(write_pipeline_output(dir, result, o, output));
      },
      py::arg("dir"), py::arg("result"), py::arg("options") = static_cast<const PipelineOptions*>(nullptr),
      py::arg("overwrite") = false, py::arg("intermediates") = false,
      "Writes the output folder atomically (options default to the run's own).");
}

}  // namespace g2p::python
