// Evaluation: confusion matrices, segmentation scored over a labelled set
// (g2p.evaluate_segmentation, as `g2p eval seg`), two such runs compared
// (g2p.compare_segmentation_files, as `g2p eval compare`) and mass errors (as
// `g2p eval mass`).
#include <optional>

#include "bindings.h"

namespace g2p::python {

void bind_eval(py::module_& m);

namespace {

py::object json_loads(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

// (classes, classes + 1) counts: rows the truth, columns the prediction, the
// last column "unknown".
py::array_t<double> matrix_counts(const ConfusionMatrix& c) {
  const int n = c.num_classes();
  py::array_t<double> a({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(n + 1)});
  double* out = a.mutable_data();
  for (int t = 0; t < n; ++t) {
    for (int p = 0; p < n; ++p) out[t * (n + 1) + p] = c.count(t, p);
    out[t * (n + 1) + n] = c.count(t, kUnknownLabel);
  }
  return a;
}

py::dict model_dict(const SegmentationModelEval& m, const MaterialTable& table, const std::string& refiner) {
  py::dict d;
  d["key"] = m.key;
  d["2d"] = json_loads(m.pixels.to_json(table));
  d["3d"] = json_loads(m.faces.to_json(table));
  d["kind"] = m.kind;
  d["kind_prior_applied"] = m.kind_prior_applied;
  if (m.refined) {
    py::dict r;
    r["refiner"] = refiner;
    if (!m.refine_error.empty()) {
      r["error"] = m.refine_error;
    } else {
      r["notes"] = m.refine_notes;
      r["changed_faces"] = m.refine_changed_faces;
    }
    d["refine"] = r;
  }
  d["warnings"] = m.warnings;
  return d;
}

py::dict mass_dict(const MassErrors& e) {
  py::dict d;
  d["objects"] = e.objects;
  d["ade_kg"] = e.ade_kg;
  d["alde"] = e.alde;
  d["ape"] = e.ape;
  d["mnre"] = e.mnre;
  return d;
}

// The options from `options` or from keywords, never both (as g2p.Pipeline).
SegmentationEvalOptions eval_options(const py::object& options, const py::kwargs& kwargs) {
  if (!options.is_none() && kwargs.size() > 0)
    throw py::type_error("evaluate_segmentation: give either options or keyword options, not both");
  return options.is_none() ? from_kwargs<SegmentationEvalOptions>(kwargs) : options.cast<SegmentationEvalOptions>();
}

}  // namespace

void bind_eval(py::module_& m) {
  py::class_<ConfusionMatrix>(m, "ConfusionMatrix",
                              "Counts of (true class, predicted class), pixels or faces weighted by area; IoU per "
                              "class = TP / (TP + FP + FN), mIoU over the classes present in the truth (eval.h).")
      .def(py::init<int>(), py::arg("num_classes") = 0)
      .def_property_readonly("num_classes", &ConfusionMatrix::num_classes)
      .def("add", py::overload_cast<int, int, double>(&ConfusionMatrix::add), py::arg("truth"), py::arg("predicted"),
           py::arg("weight") = 1.0)
      .def("merge", &ConfusionMatrix::merge, py::arg("other"), py::arg("weight") = 1.0)
      .def("count", &ConfusionMatrix::count, py::arg("truth"), py::arg("predicted"))
      .def("present", &ConfusionMatrix::present, py::arg("label"), "whether the class occurs in the truth")
      .def("iou", &ConfusionMatrix::iou, py::arg("label"), "NaN when the class is neither true nor predicted")
      .def_property_readonly("miou", &ConfusionMatrix::mean_iou, "over the classes present; NaN when none")
      .def_property_readonly("accuracy", &ConfusionMatrix::accuracy, "correct weight / labelled weight")
      .def_property_readonly("total", &ConfusionMatrix::total, "labelled (non-void) weight")
      .def_property_readonly("counts", &matrix_counts,
                             "(classes, classes + 1) float64: rows the truth, columns the prediction, the last "
                             "column unknown")
      .def(
          "table", [](const ConfusionMatrix& c, const MaterialTable& t) { return c.table(t); },
          py::arg("table") = MaterialTable::paper_default(), "IoU % per class present, then mIoU, as Markdown")
      .def(
          "to_json", [](const ConfusionMatrix& c, const MaterialTable& t) { return json_loads(c.to_json(t)); },
          py::arg("table") = MaterialTable::paper_default(), "classes, iou, miou, accuracy and the matrix as a dict");

  py::class_<SegmentationEvalOptions>(
      m, "SegmentationEvalOptions",
      "What g2p.evaluate_segmentation scores, and how (the `g2p eval seg` flags). Keyword construction: "
      "g2p.SegmentationEvalOptions(assets='../shared/assets', models=['Avocado'], segmenter='oracle'); nested "
      "structs are edited in place (options.views.num_views = 3).")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<SegmentationEvalOptions>(kw); }))
      .def_readwrite("assets", &SegmentationEvalOptions::assets,
                     "folder of the models: KEY/KEY.glb, or KEY as a file path inside it")
      .def_readwrite("truth", &SegmentationEvalOptions::truth, "labels.json; '' = ASSETS/labels.json")
      .def_readwrite("models", &SegmentationEvalOptions::models, "keys to score, in order; [] = every key")
      .def_readwrite("split", &SegmentationEvalOptions::split, "only keys whose entry has this split; '' = any")
      .def_readwrite("materials", &SegmentationEvalOptions::materials, "g2p.MaterialTable: the classes scored")
      .def_readwrite("anonymize_names", &SegmentationEvalOptions::anonymize_names)
      .def_readwrite("base_color_only", &SegmentationEvalOptions::base_color_only)
      .def_readwrite("renderer", &SegmentationEvalOptions::renderer)
      .def_readwrite("views", &SegmentationEvalOptions::views, "g2p.ViewOptions")
      .def_readwrite("segmenter", &SegmentationEvalOptions::segmenter, "the scored backend (a g2p.BackendChoice)")
      .def_readwrite("project", &SegmentationEvalOptions::project,
                     "g2p.ProjectOptions: project.vote.mode = g2p.VoteMode.SOFT for soft votes")
      .def_readwrite("refiner", &SegmentationEvalOptions::refiner, "after voting; 'none' (default) = project alone")
      .def_readwrite("identifier", &SegmentationEvalOptions::identifier, "'none' (default), auto, names, ...")
      .def_readwrite("object_from_names", &SegmentationEvalOptions::object_from_names)
      .def_readwrite("kind_confidence", &SegmentationEvalOptions::kind_confidence)
      .def_readwrite("kind_prior", &SegmentationEvalOptions::kind_prior)
      .def_readwrite("region_features", &SegmentationEvalOptions::region_features,
                     "also write every region's features to this CSV; '' = none");

  py::class_<SegmentationEval>(m, "SegmentationEval",
                               "A set's scores: total (2D, per pixel), total_3d (per face by area), "
                               "total_3d_per_model (every model weighing the same) and per model.")
      .def_readonly("options", &SegmentationEval::options)
      .def_readonly("total", &SegmentationEval::total)
      .def_readonly("total_3d", &SegmentationEval::total_3d)
      .def_readonly("total_3d_per_model", &SegmentationEval::total_3d_per_model)
      .def_property_readonly(
          "miou", [](const SegmentationEval& e) { return e.total_3d_per_model.mean_iou(); },
          "total_3d_per_model's mIoU (every model weighing the same)")
      .def_property_readonly(
          "interval",
          [](const SegmentationEval& e) -> py::object {
            if (!e.interval) return py::none();
            py::dict d;
            d["miou"] = e.interval->miou;
            d["low"] = e.interval->low;
            d["high"] = e.interval->high;
            d["confidence"] = e.interval->confidence;
            d["resamples"] = e.interval->resamples;
            return std::move(d);
          },
          "the bootstrap interval of the per-model mIoU as a dict, or None")
      .def_property_readonly("keys",
                             [](const SegmentationEval& e) {
                               std::vector<std::string> keys;
                               for (const SegmentationModelEval& s : e.models) keys.push_back(s.key);
                               return keys;
                             })
      .def_property_readonly(
          "models",
          [](const SegmentationEval& e) {
            py::list l;
            for (const SegmentationModelEval& s : e.models)
              l.append(model_dict(s, e.options.materials, e.options.refiner.name));
            return l;
          },
          "per model a dict: key, 2d, 3d (ConfusionMatrix.to_json), kind, kind_prior_applied, refine, warnings")
      .def(
          "matrices",
          [](const SegmentationEval& e, bool faces) {
            std::vector<ConfusionMatrix> out;
            for (const SegmentationModelEval& s : e.models) out.push_back(faces ? s.faces : s.pixels);
            return out;
          },
          py::arg("faces") = true, "the models' ConfusionMatrix, per face (3D) or per pixel (faces=False)")
      .def(
          "to_json", [](const SegmentationEval& e) { return e.to_json(); },
          "the text `g2p eval seg --json` writes (without its final newline)")
      .def(
          "json", [](const SegmentationEval& e) { return json_loads(e.to_json()); }, "to_json() as a dict")
      .def("to_text", &SegmentationEval::to_text,
           "the tables, interval and calibration `g2p eval seg` prints after the models")
      .def("__str__", &SegmentationEval::to_text);

  m.def(
      "evaluate_segmentation",
      [](const py::object& options, const py::object& on_model, const py::kwargs& kwargs) {
        SegmentationEvalOptions o = eval_options(options, kwargs);
        if (!on_model.is_none() && !PyCallable_Check(on_model.ptr()))
          throw py::type_error("on_model must be callable (it receives each model's dict)");
        // The models' callback and Ctrl-C need the GIL: a failed call or a
        // signal cancels the evaluation, and the error is raised when it returns.
        RunContext context;
        std::optional<py::error_already_set> error;
        const std::string refiner = o.refiner.name;
        const MaterialTable table = o.materials;
        o.on_model = [&](const SegmentationModelEval& scored) {
          py::gil_scoped_acquire gil;
          if (error) return;
          try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (!on_model.is_none()) {
              py::object keep_going = on_model(model_dict(scored, table, refiner));
              if (py::isinstance<py::bool_>(keep_going) && !keep_going.cast<bool>()) context.cancel();
            }
          } catch (py::error_already_set& e) {
            error.emplace(std::move(e));
            context.cancel();
          }
        };
        std::optional<Result<SegmentationEval>> result;
        {
          py::gil_scoped_release release;
          result.emplace(evaluate_segmentation(o, &context));
        }
        if (error) throw std::move(*error);
        SegmentationEval out = unwrap(std::move(*result));
        out.options.on_model = nullptr;  // it refers to this call's locals
        return out;
      },
      py::arg("options") = py::none(), py::kw_only(), py::arg("on_model") = py::none(),
      "Scores a segmenter over a labelled set as `g2p eval seg` does: each model through the pipeline to project "
      "(or refine), per pixel and per face against labels.json. Give a g2p.SegmentationEvalOptions or its fields "
      "as keywords (assets=, models=, segmenter=, views=g2p.ViewOptions(num_views=3, width=128, height=128), "
      "...). on_model(dict) is called after each model; returning False cancels (g2p.Cancelled). The GIL is "
      "released meanwhile. A bad option raises g2p.InvalidArgumentError or g2p.NotFoundError naming it.");

  m.def(
      "compare_segmentation_files",
      [](const std::string& a, const std::string& b, double confidence, int resamples, unsigned seed) {
        SegmentationComparisonOptions o;
        o.confidence = confidence;
        o.resamples = resamples;
        o.seed = seed;
        const SegmentationComparison c = unwrap(compare_segmentation_files(a, b, o));
        py::dict d = json_loads(c.to_json());
        d["label_a"] = c.label_a;
        d["label_b"] = c.label_b;
        d["differing_conditions"] = c.differing_conditions;
        d["text"] = c.to_text();
        return d;
      },
      py::arg("a"), py::arg("b"), py::kw_only(), py::arg("confidence") = SegmentationComparisonOptions{}.confidence,
      py::arg("resamples") = SegmentationComparisonOptions{}.resamples,
      py::arg("seed") = SegmentationComparisonOptions{}.seed,
      "Is B better than A? Two `g2p eval seg --json` files (SegmentationEval.to_json()) of the same models "
      "compared as `g2p eval compare` does: the paired bootstrap of the per-face mIoU difference. A dict: what "
      "`--json` writes (miou_a, miou_b, difference, low, high, confidence, resamples, models, iou_per_class), "
      "label_a, label_b, differing_conditions ('' when none) and text (what the command prints). Files of other "
      "models or ground truth raise g2p.InvalidArgumentError, a missing one g2p.NotFoundError.");

  m.def(
      "mass_errors",
      [](const std::vector<double>& predicted_kg, const std::vector<double>& true_kg) {
        return mass_dict(unwrap(mass_errors(predicted_kg, true_kg)));
      },
      py::arg("predicted_kg"), py::arg("true_kg"),
      "ADE (kg), ALDE, APE and MnRE averaged over objects (NeRF2Physics' metrics) as a dict.");
  m.def(
      "mass_errors_from_csv", [](const std::string& path) { return mass_dict(unwrap(mass_errors_from_csv(path))); },
      py::arg("path"), "mass_errors over a CSV object,predicted_kg,true_kg (`g2p eval mass`).");
}

}  // namespace g2p::python
