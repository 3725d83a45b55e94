// The five stage interfaces (Renderer, Segmenter, Refiner, Completer,
// PropertyEstimator) with trampolines so Python classes can implement them,
// the backend registries, and each stage as a function.
//
// A trampoline runs on whatever thread the C++ pipeline calls it from, with
// the GIL released; it takes the GIL, calls the Python method, checks what it
// returned, and turns any Python exception into an error Status (the
// traceback in its message) so that the pipeline fails or degrades as it
// would for a C++ backend instead of unwinding through C++.
#include "bindings.h"

namespace g2p::python {

namespace {

// Runs a trampoline's body (GIL held) and converts whatever it throws.
template <typename Base, typename Fn>
auto call_guarded(const Base* self, const char* method, Fn&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const py::error_already_set& e) {
    return status_from_python(e, python_class_name(self) + "." + method);
  } catch (const StatusError& e) {
    return e.status();
  } catch (const std::exception& e) {
    return Status::Internal(python_class_name(self) + "." + method + ": " + e.what());
  }
}

std::string shape_of(const py::handle& object) {
  return py::hasattr(object, "shape") ? std::string(py::str(object.attr("shape"))) : "no shape";
}

std::string dtype_of(const py::handle& object) {
  return py::hasattr(object, "dtype") ? std::string(py::str(object.attr("dtype")))
                                      : std::string(py::str(py::type::handle_of(object).attr("__name__")));
}

std::string shape_text(std::vector<py::ssize_t> dims) {
  std::string s = "(";
  for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + (dims.size() == 1 ? ",)" : ")");
}

// What a Python segment() returned, checked against the view: a labels array
// (H, W) of an integer dtype, a (labels, probabilities) pair, or a LabelMap.
Status label_map_from_python(const py::object& returned, const View& view, int num_classes, const std::string& where,
                             LabelMap& out) {
  const py::ssize_t h = view.camera.height, w = view.camera.width;
  py::object labels = returned, probabilities = py::none();
  if (py::isinstance<LabelMap>(returned)) {
    const LabelMap& map = returned.cast<const LabelMap&>();
    labels = image_to_numpy(map.labels, true);
    probabilities = image_to_numpy(map.probabilities, false);
  } else if (py::isinstance<py::tuple>(returned) || py::isinstance<py::list>(returned)) {
    py::sequence pair = returned;
    if (pair.size() != 2)
      return Status::Internal(where + ": expected labels or (labels, probabilities), got a sequence of " +
                              std::to_string(pair.size()));
    labels = pair[0], probabilities = pair[1];
  }
  const std::string expected_labels =
      "expected labels of shape " + shape_text({h, w}) + " (the view's height, width) with an integer dtype";
  py::array any = py::array::ensure(labels);
  if (!any || any.ndim() != 2 || any.shape(0) != h || any.shape(1) != w || !has_integer_dtype(any))
    return Status::Internal(where + ": " + expected_labels + ", got " + shape_of(labels) + " " + dtype_of(labels));
  auto typed = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>::ensure(any);
  out.labels.reset(static_cast<int>(w), static_cast<int>(h), 1);
  std::copy(typed.data(), typed.data() + typed.size(), out.labels.data());
  for (std::int32_t v : out.labels.storage())
    if (v < kUnknownLabel || (num_classes > 0 && v >= num_classes))
      return Status::Internal(where + ": label " + std::to_string(v) + " outside [-1, " + std::to_string(num_classes) +
                              ") (the material table's classes; -1 = unknown)");
  out.probabilities.clear();
  if (!probabilities.is_none()) {
    py::array p = py::array::ensure(probabilities);
    const py::ssize_t c = num_classes;
    if (!p || p.ndim() != 3 || p.shape(0) != h || p.shape(1) != w || (c > 0 && p.shape(2) != c))
      return Status::Internal(where + ": expected probabilities of shape " + shape_text({h, w, c}) + ", got " +
                              shape_of(probabilities));
    out.probabilities = image_from_numpy<float>(p, 0, where + " probabilities");
  }
  return Status::Ok();
}

// ---- Stage inputs as Python sees them -------------------------------------------

// A stage input handed to a Python method. It points into the running stage,
// so it is valid only during that call: afterwards every attribute raises
// (its values are copied out on access, so arrays taken during the call stay
// valid).
template <typename Input>
struct InputView {
  const Input* input = nullptr;
  const Input& get() const {
    if (!input) throw py::value_error("a stage input is only valid during the call that received it");
    return *input;
  }
};
using RefineInputView = InputView<RefineInput>;
using CompletionInputView = InputView<CompletionInput>;
using PropertyInputView = InputView<PropertyInput>;

// Calls `method` with a fresh view of `input` and expires the view afterwards.
template <typename Input>
py::object call_with_input(const py::function& method, const Input& input) {
  py::object view = py::cast(InputView<Input>{&input});
  auto* raw = view.cast<InputView<Input>*>();
  struct Expire {
    InputView<Input>* view;
    ~Expire() { view->input = nullptr; }
  } expire{raw};
  return method(view);
}

std::vector<View> copy_views(const std::vector<View>* views) { return views ? *views : std::vector<View>{}; }

// ---- Trampolines ---------------------------------------------------------------

class PyRenderer : public Renderer {
 public:
  Status set_model(const Model& model) override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "set_model", [&]() -> Status {
      if (py::function f = py::get_override(static_cast<const Renderer*>(this), "set_model")) f(model);
      return Status::Ok();
    });
  }
  Status render_into(const Camera& camera, const RenderOptions& options, View& view) const override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "render", [&]() -> Status {
      py::function f = py::get_override(static_cast<const Renderer*>(this), "render");
      if (!f) return Status::Unsupported(python_class_name(this) + " does not define render(camera, options)");
      py::object returned = f(camera, options);
      if (!py::isinstance<View>(returned))
        return Status::Internal(python_class_name(this) + ".render: expected a g2p.View, got " + dtype_of(returned));
      View v = returned.cast<View>();
      if (v.face_id.width() != camera.width || v.face_id.height() != camera.height)
        return Status::Internal(python_class_name(this) + ".render: the view's face_id must have the camera's shape " +
                                shape_text({camera.height, camera.width}) + ", got " +
                                shape_text({v.face_id.height(), v.face_id.width()}));
      v.camera = camera;
      view = std::move(v);
      return Status::Ok();
    });
  }
};

class PySegmenter : public Segmenter {
 public:
  Status configure(const BackendSettings& settings) override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "configure", [&]() -> Status {
      py::function f = py::get_override(static_cast<const Segmenter*>(this), "configure");
      if (!f) return Segmenter::configure(settings);
      f(settings);
      return Status::Ok();
    });
  }
  Status set_model(const Model& model, const MaterialTable& table) override {
    py::gil_scoped_acquire gil;
    num_classes_ = table.size();
    return call_guarded(this, "set_model", [&]() -> Status {
      if (py::function f = py::get_override(static_cast<const Segmenter*>(this), "set_model")) f(model, table);
      return Status::Ok();
    });
  }
  Status segment_into(const View& view, LabelMap& out) const override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "segment", [&]() -> Status {
      py::function f = py::get_override(static_cast<const Segmenter*>(this), "segment");
      if (!f) return Status::Unsupported(python_class_name(this) + " does not define segment(view)");
      return label_map_from_python(f(view), view, num_classes_, python_class_name(this) + ".segment", out);
    });
  }
  std::vector<std::string> warnings() const override {
    py::gil_scoped_acquire gil;
    py::function f = py::get_override(static_cast<const Segmenter*>(this), "warnings");
    if (!f) return Segmenter::warnings();
    try {
      return f().cast<std::vector<std::string>>();
    } catch (const std::exception& e) {  // a warning about the warnings, not a failed run
      return {python_class_name(this) + ".warnings() did not return a list of str: " + e.what()};
    }
  }
  std::vector<std::uint8_t> image_decided_faces() const override {
    py::gil_scoped_acquire gil;
    py::function f = py::get_override(static_cast<const Segmenter*>(this), "image_decided_faces");
    if (!f) return Segmenter::image_decided_faces();
    // Not said (None), or per face 0/1; anything else is not said either:
    // the `regions` refiner then treats every face alike.
    py::object returned = f();
    if (returned.is_none()) return {};
    try {
      const std::vector<int> faces = int_vector_from_numpy(returned, python_class_name(this) + ".image_decided_faces");
      std::vector<std::uint8_t> out(faces.size());
      for (std::size_t i = 0; i < faces.size(); ++i) out[i] = faces[i] != 0 ? 1 : 0;
      return out;
    } catch (const std::exception&) {
      return {};
    }
  }

 private:
  int num_classes_ = 0;  // of the table given to set_model; 0 = not checked
};

class PyRefiner : public Refiner {
 public:
  Status configure(const BackendSettings& settings) override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "configure", [&]() -> Status {
      py::function f = py::get_override(static_cast<const Refiner*>(this), "configure");
      if (!f) return Refiner::configure(settings);
      f(settings);
      return Status::Ok();
    });
  }
  Result<RefineResult> refine(const RefineInput& input) const override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "refine", [&]() -> Result<RefineResult> {
      py::function f = py::get_override(static_cast<const Refiner*>(this), "refine");
      if (!f) return Status::Unsupported(python_class_name(this) + " does not define refine(input)");
      const std::string where = python_class_name(this) + ".refine";
      py::object returned = call_with_input(f, input);
      const int num_faces = input.mesh ? input.mesh->num_faces() : 0;
      const int num_classes = input.table ? input.table->size() : 0;
      RefineResult result;
      if (py::isinstance<RefineResult>(returned)) {
        result = returned.cast<RefineResult>();
      } else {
        result.labels = int_vector_from_numpy(returned, where + " labels");
      }
      if (static_cast<int>(result.labels.size()) != num_faces)
        return Status::Internal(where + ": expected labels of shape (" + std::to_string(num_faces) +
                                ",) (one per face), got " + std::to_string(result.labels.size()));
      for (int v : result.labels)
        if (v < kUnknownLabel || (num_classes > 0 && v >= num_classes))
          return Status::Internal(where + ": label " + std::to_string(v) + " outside [-1, " +
                                  std::to_string(num_classes) + ")");
      if (result.changes.empty() && input.labels != nullptr) {
        const std::vector<int>& before = input.labels->label;
        for (int face = 0; face < num_faces && face < static_cast<int>(before.size()); ++face)
          if (before[face] != result.labels[face])
            result.changes.push_back(LabelChange{face, before[face], result.labels[face], python_class_name(this)});
      }
      return result;
    });
  }
};

class PyCompleter : public Completer {
 public:
  Status configure(const BackendSettings& settings) override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "configure", [&]() -> Status {
      py::function f = py::get_override(static_cast<const Completer*>(this), "configure");
      if (!f) return Completer::configure(settings);
      f(settings);
      return Status::Ok();
    });
  }
  Result<Completion> complete(const CompletionInput& input) const override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "complete", [&]() -> Result<Completion> {
      const std::string name = python_class_name(this);
      const std::size_t num_parts = input.parts ? input.parts->size() : 0;
      if (py::function f = py::get_override(static_cast<const Completer*>(this), "complete")) {
        py::object returned = call_with_input(f, input);
        if (!py::isinstance<Completion>(returned))
          return Status::Internal(name + ".complete: expected a g2p.Completion, got " + dtype_of(returned));
        Completion completion = returned.cast<Completion>();
        if (completion.parts.size() != num_parts)
          return Status::Internal(name + ".complete: expected " + std::to_string(num_parts) + " completed parts, got " +
                                  std::to_string(completion.parts.size()));
        return completion;
      }
      py::function close = py::get_override(static_cast<const Completer*>(this), "close_part");
      if (!close) return Status::Unsupported(name + " defines neither complete(input) nor close_part(part, patch)");
      py::object self = py::cast(static_cast<const Completer*>(this), py::return_value_policy::reference);
      const double tolerance = py::getattr(self, "max_relative_distance", py::float_(0.25)).cast<double>();
      // The checks run in C++ without the GIL; each close_part call takes it back.
      py::gil_scoped_release release;
      return complete_each_part(input, name, tolerance, [&](int part, const Mesh& patch, CompletedPart& out) {
        py::gil_scoped_acquire again;
        return call_guarded(this, "close_part", [&]() -> Status {
          py::object returned = close(part, patch);
          if (returned.is_none())
            return Status::Unavailable(name + ".close_part left part " + std::to_string(part) + " open");
          if (py::isinstance<Mesh>(returned)) {
            out.mesh = returned.cast<Mesh>();
          } else if (py::isinstance<py::tuple>(returned) && py::len(returned) == 2) {
            py::tuple pair = returned;
            out.mesh.positions = rows_from_numpy<Eigen::Vector3f>(pair[0], "close_part positions");
            out.mesh.triangles = rows_from_numpy<Eigen::Vector3i>(pair[1], "close_part triangles");
          } else {
            return Status::Internal(name + ".close_part: expected a g2p.Mesh, (positions, triangles) or None, got " +
                                    dtype_of(returned));
          }
          return validate(out.mesh);
        });
      });
    });
  }
};

// Defaults for a part from the material table, before a Python estimator's dict overrides them.
PartProperties table_defaults(const PropertyInput& input) {
  PartProperties p;
  p.label = input.part ? input.part->label : kUnknownLabel;
  if (input.table && input.table->valid_label(p.label)) {
    const MaterialClass& c = (*input.table)[p.label];
    p.density_kg_m3 = c.density_kg_m3, p.density_min_kg_m3 = c.density_min_kg_m3;
    p.density_max_kg_m3 = c.density_max_kg_m3, p.structure = c.structure;
    p.wall_thickness_m = c.wall_thickness_m, p.friction_static = c.friction_static;
    p.friction_dynamic = c.friction_dynamic, p.restitution = c.restitution;
  }
  return p;
}

// A dict from a Python estimate(): the table's values for the part's class,
// overridden (and marked ValueSource.USER) by the keys given.
PartProperties properties_from_dict(const py::dict& d, const PropertyInput& input, const std::string& where) {
  const PartProperties defaults = table_defaults(input);
  py::object object = py::cast(defaults);
  for (const auto& item : d) {
    const std::string key = py::str(item.first);
    if (key.empty() || key[0] == '_' || !py::hasattr(object, key.c_str()))
      throw py::key_error(where + ": unknown property '" + key + "'");
    py::object value = py::reinterpret_borrow<py::object>(item.second);
    if (key == "structure" && py::isinstance<py::str>(value)) {
      const std::string s = py::str(value);
      if (s != "solid" && s != "hollow") throw py::value_error(where + ": structure must be 'solid' or 'hollow'");
      value = py::cast(s == "solid" ? Structure::kSolid : Structure::kHollow);
    }
    py::setattr(object, item.first, value);
  }
  PartProperties p = object.cast<PartProperties>();
  auto given = [&](const char* key) { return d.contains(key); };
  if (given("density_kg_m3")) {
    if (!given("density_source")) p.density_source = ValueSource::kUser;
    // The table's relative range around the new nominal value, unless given.
    const double scale = defaults.density_kg_m3 > 0 ? p.density_kg_m3 / defaults.density_kg_m3 : 0.0;
    if (!given("density_min_kg_m3"))
      p.density_min_kg_m3 = scale > 0 ? defaults.density_min_kg_m3 * scale : p.density_kg_m3;
    if (!given("density_max_kg_m3"))
      p.density_max_kg_m3 = scale > 0 ? defaults.density_max_kg_m3 * scale : p.density_kg_m3;
  }
  if (given("structure") && !given("structure_source")) p.structure_source = ValueSource::kUser;
  if (given("wall_thickness_m") && !given("thickness_source")) p.thickness_source = ValueSource::kUser;
  for (const char* k : {"friction_static", "friction_dynamic", "restitution", "solref", "solimp"})
    if (given(k) && !given("contact_source")) p.contact_source = ValueSource::kUser;
  return p;
}

class PyPropertyEstimator : public PropertyEstimator {
 public:
  Status configure(const BackendSettings& settings) override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "configure", [&]() -> Status {
      py::function f = py::get_override(static_cast<const PropertyEstimator*>(this), "configure");
      if (!f) return PropertyEstimator::configure(settings);
      f(settings);
      return Status::Ok();
    });
  }
  Result<PartProperties> estimate(const PropertyInput& input) const override {
    py::gil_scoped_acquire gil;
    return call_guarded(this, "estimate", [&]() -> Result<PartProperties> {
      py::function f = py::get_override(static_cast<const PropertyEstimator*>(this), "estimate");
      const std::string where = python_class_name(this) + ".estimate";
      if (!f) return Status::Unsupported(python_class_name(this) + " does not define estimate(input)");
      py::object returned = call_with_input(f, input);
      if (py::isinstance<PartProperties>(returned)) {
        PartProperties p = returned.cast<PartProperties>();
        if (p.label == kUnknownLabel && input.part) p.label = input.part->label;
        return p;
      }
      if (py::isinstance<py::dict>(returned)) return properties_from_dict(returned, input, where);
      return Status::Internal(where + ": expected a g2p.PartProperties or a dict, got " + dtype_of(returned));
    });
  }
};

const MaterialTable& table_or_default(const MaterialTable* table) {
  return table ? *table : MaterialTable::paper_default();
}

}  // namespace

void bind_stages(py::module_& m) {
  const MaterialTable* no_table = nullptr;

  // ---- Stage inputs ----
  py::class_<RefineInputView>(m, "RefineInput", "What a refiner looks at; valid only during refine().")
      .def_property_readonly("num_faces", [](const RefineInputView& v) { return v.get().mesh->num_faces(); })
      .def_property_readonly("num_classes", [](const RefineInputView& v) { return v.get().table->size(); })
      .def_property_readonly("mesh", [](const RefineInputView& v) { return *v.get().mesh; })
      .def_property_readonly("graph", [](const RefineInputView& v) { return *v.get().graph; })
      .def_property_readonly(
          "labels", [](const RefineInputView& v) { return vector_to_numpy(v.get().labels->label); },
          "(M,) int32 projected class per face")
      .def_property_readonly("confidence",
                             [](const RefineInputView& v) { return vector_to_numpy(v.get().labels->confidence); })
      .def_property_readonly("seen", [](const RefineInputView& v) { return vector_to_numpy(v.get().labels->seen); })
      .def_property_readonly(
          "votes", [](const RefineInputView& v) { return dense_votes(*v.get().votes); },
          "(M, C) float32 vote histograms")
      .def_property_readonly("views", [](const RefineInputView& v) { return copy_views(v.get().views); })
      .def_property_readonly("table", [](const RefineInputView& v) { return *v.get().table; })
      .def_property_readonly(
          "image_decided",
          [](const RefineInputView& v) -> py::object {
            const std::vector<std::uint8_t>* d = v.get().image_decided;
            if (d == nullptr || d->empty()) return py::none();
            return vector_to_numpy(*d);
          },
          "(M,) uint8, 1 where the segmenter labelled the face from the image alone; None when not known");
  py::class_<CompletionInputView>(m, "CompletionInput", "The object and its parts; valid only during complete().")
      .def_property_readonly("mesh", [](const CompletionInputView& v) { return *v.get().mesh; })
      .def_property_readonly("parts", [](const CompletionInputView& v) { return *v.get().parts; })
      .def_property_readonly("num_parts", [](const CompletionInputView& v) { return v.get().parts->size(); })
      .def_property_readonly("table", [](const CompletionInputView& v) { return table_or_default(v.get().table); })
      .def(
          "patch",
          [](const CompletionInputView& v, std::size_t part) {
            const CompletionInput& in = v.get();
            if (part >= in.parts->size()) throw py::index_error("part " + std::to_string(part));
            return part_patch(*in.mesh, (*in.parts)[part]);
          },
          "The part's own faces as a Mesh (its open patch).");
  py::class_<PropertyInputView>(m, "PropertyInput", "One part to estimate; valid only during estimate().")
      .def_property_readonly("label", [](const PropertyInputView& v) { return v.get().part->label; })
      .def_property_readonly("class_name",
                             [](const PropertyInputView& v) -> py::object {
                               const PropertyInput& in = v.get();
                               if (!in.table || !in.table->valid_label(in.part->label)) return py::none();
                               return py::str((*in.table)[in.part->label].name);
                             })
      .def_property_readonly(
          "material",
          [](const PropertyInputView& v) -> py::object {
            const PropertyInput& in = v.get();
            if (!in.table || !in.table->valid_label(in.part->label)) return py::none();
            return py::cast((*in.table)[in.part->label]);
          },
          "The table's MaterialClass of the part's label (its default values), or None")
      .def_property_readonly("part_index",
                             [](const PropertyInputView& v) {
                               const PropertyInput& in = v.get();
                               return in.all_parts ? static_cast<int>(in.part - in.all_parts->data()) : -1;
                             })
      .def_property_readonly("faces", [](const PropertyInputView& v) { return vector_to_numpy(v.get().part->faces); })
      .def_property_readonly("area_m2", [](const PropertyInputView& v) { return v.get().part->area_m2; })
      .def_property_readonly("object", [](const PropertyInputView& v) { return *v.get().object; })
      .def_property_readonly("patch",
                             [](const PropertyInputView& v) { return part_patch(*v.get().object, *v.get().part); })
      .def_property_readonly(
          "closed",
          [](const PropertyInputView& v) -> py::object {
            const PropertyInput& in = v.get();
            return in.completed ? py::cast(in.completed->mesh) : py::none();
          },
          "The part's closed Mesh from the complete stage, or None")
      .def_property_readonly("completed_ok",
                             [](const PropertyInputView& v) { return v.get().completed && v.get().completed->ok; })
      .def_property_readonly(
          "volume_m3",
          [](const PropertyInputView& v) { return v.get().completed ? v.get().completed->checks.volume_m3 : 0.0; })
      .def_property_readonly("table", [](const PropertyInputView& v) { return table_or_default(v.get().table); })
      .def_property_readonly("views", [](const PropertyInputView& v) { return copy_views(v.get().views); });

  // ---- Interfaces ----
  py::class_<Renderer, PyRenderer, std::shared_ptr<Renderer>>(
      m, "Renderer",
      "The render stage. Subclass it: set_model(self, model) (optional) and render(self, camera, options) -> "
      "g2p.View with at least face_id and rgb of the camera's shape.")
      .def(py::init<>())
      .def(
          "set_model",
          [](Renderer& r, const Model& model) {
            py::gil_scoped_release release;
            throw_if_error(r.set_model(model));
          },
          py::keep_alive<1, 2>(), "The renderer keeps a reference to the model.")
      .def(
          "render",
          [](const Renderer& r, const Camera& camera, const RenderOptions& options) {
            py::gil_scoped_release release;
            return unwrap(r.render(camera, options));
          },
          py::arg("camera"), py::arg("options") = RenderOptions());

  py::class_<Segmenter, PySegmenter, std::shared_ptr<Segmenter>>(
      m, "Segmenter",
      "The segment stage. Subclass it (call super().__init__()): segment(self, view) returns labels (H, W) of an "
      "integer dtype (-1 = unknown), or (labels, probabilities (H, W, C) float32), or a g2p.LabelMap; optional "
      "set_model(self, model, table), configure(self, settings) and warnings(self) (a list of str: what degraded, "
      "which the pipeline adds to PipelineResult.warnings).")
      .def(py::init<>())
      .def(
          "settings", [](Segmenter& s) { return settings_to_python(s.settings().info()); },
          "Its settings with their current values: a list of dicts (key, type, unit, range, value, help).")
      .def("configure", [](Segmenter& s, const BackendSettings& settings) { throw_if_error(s.configure(settings)); })
      .def(
          "set_model",
          [](Segmenter& s, const Model& model, const MaterialTable& table) {
            py::gil_scoped_release release;
            throw_if_error(s.set_model(model, table));
          },
          py::arg("model"), py::arg("table") = MaterialTable::paper_default(), py::keep_alive<1, 2>(),
          py::keep_alive<1, 3>())
      .def(
          "segment",
          [](const Segmenter& s, const View& view) {
            py::gil_scoped_release release;
            return unwrap(s.segment(view));
          },
          py::arg("view"), "A LabelMap for the view (call set_model first).")
      .def(
          "warnings", [](const Segmenter& s) { return s.warnings(); },
          "What degraded since configure and set_model (hybrid without its network says why here).")
      .def(
          "image_decided_faces",
          [](const Segmenter& s) -> py::object {
            const std::vector<std::uint8_t> d = s.image_decided_faces();
            if (d.empty()) return py::none();
            return vector_to_numpy(d);
          },
          "After set_model: (M,) uint8, 1 where the image alone labels the face (a network), 0 where names or "
          "other evidence do; None when the backend does not say. The regions refiner decides only the image's "
          "regions.");

  py::class_<Refiner, PyRefiner, std::shared_ptr<Refiner>>(
      m, "Refiner",
      "The refine stage. Subclass it: refine(self, input: g2p.RefineInput) returns labels (M,) of an integer "
      "dtype, one per face, or a g2p.RefineResult. A failure (an exception) keeps the projected labels; the "
      "pipeline reports the stage as failed and adds a warning.")
      .def(py::init<>())
      .def(
          "settings", [](Refiner& r) { return settings_to_python(r.settings().info()); },
          "Its settings with their current values: a list of dicts (key, type, unit, range, value, help).")
      .def("configure", [](Refiner& r, const BackendSettings& settings) { throw_if_error(r.configure(settings)); })
      .def(
          "refine",
          [](const Refiner& r, const RefineInputView& input) {
            const RefineInput& in = input.get();
            py::gil_scoped_release release;
            return unwrap(r.refine(in));
          },
          "Runs this (C++) backend on an input received by a Python refiner: wrap and post-process.");

  py::class_<Completer, PyCompleter, std::shared_ptr<Completer>>(
      m, "Completer",
      "The complete stage. Subclass it and define either close_part(self, part, patch: g2p.Mesh) returning the "
      "closed g2p.Mesh, (positions, triangles) or None (libg2p checks each one; attribute max_relative_distance, "
      "default 0.25, bounds its distance to the patch) or complete(self, input) returning a g2p.Completion.")
      .def(py::init<>())
      .def(
          "settings", [](Completer& c) { return settings_to_python(c.settings().info()); },
          "Its settings with their current values: a list of dicts (key, type, unit, range, value, help).")
      .def("configure", [](Completer& c, const BackendSettings& settings) { throw_if_error(c.configure(settings)); })
      .def("complete", [](const Completer& c, const CompletionInputView& input) {
        const CompletionInput& in = input.get();
        py::gil_scoped_release release;
        return unwrap(c.complete(in));
      });

  py::class_<PropertyEstimator, PyPropertyEstimator, std::shared_ptr<PropertyEstimator>>(
      m, "PropertyEstimator",
      "The properties stage. Subclass it: estimate(self, input: g2p.PropertyInput) returns a g2p.PartProperties or "
      "a dict of its fields (missing ones come from the material table's class; given ones are marked USER), "
      "e.g. {'density_kg_m3': 7850.0, 'structure': 'solid'}.")
      .def(py::init<>())
      .def(
          "settings", [](PropertyEstimator& e) { return settings_to_python(e.settings().info()); },
          "Its settings with their current values: a list of dicts (key, type, unit, range, value, help).")
      .def("configure",
           [](PropertyEstimator& e, const BackendSettings& settings) { throw_if_error(e.configure(settings)); })
      .def("estimate", [](const PropertyEstimator& e, const PropertyInputView& input) {
        const PropertyInput& in = input.get();
        py::gil_scoped_release release;
        return unwrap(e.estimate(in));
      });

  // ---- Registries ----
  m.def(
      "backend_settings",
      [](const std::string& name) {
        py::list out;
        for (const BackendSettingsInfo& b : unwrap(describe_backend_settings(name)))
          out.append(py::dict(py::arg("stage") = to_string(b.stage), py::arg("backend") = b.backend,
                              py::arg("settings") = settings_to_python(b.settings)));
        return out;
      },
      py::arg("name"),
      "The settings of the backends called NAME in any stage, of STAGE:NAME, or of 'all': a list of dicts "
      "(stage, backend, settings: key, type, unit, range, value (the default), help).");
  m.def("renderer_names", []() { return renderer_registry().names(); });
  m.def("segmenter_names", []() { return segmenter_registry().names(); });
  m.def("refiner_names", []() { return refiner_registry().names(); });
  m.def("completer_names", []() { return completer_registry().names(); });
  m.def("estimator_names", []() { return estimator_registry().names(); });
  m.def(
      "make_renderer",
      [](const std::string& name) { return std::shared_ptr<Renderer>(unwrap(renderer_registry().create(name))); },
      py::arg("name") = PipelineOptions{}.renderer.name);
  m.def(
      "make_segmenter",
      [](const std::string& name, const py::object& settings, const py::kwargs& kwargs) {
        return std::shared_ptr<Segmenter>(
            unwrap(segmenter_registry().make(name, settings_from_python(settings, kwargs))));
      },
      py::arg("name") = PipelineOptions{}.segmenter.name, py::arg("settings") = py::none(),
      "A backend with its settings applied, as a dict or keywords (colour=False, share=0.5).");
  m.def(
      "make_refiner",
      [](const std::string& name, const py::object& settings, const py::kwargs& kwargs) {
        return std::shared_ptr<Refiner>(unwrap(refiner_registry().make(name, settings_from_python(settings, kwargs))));
      },
      py::arg("name") = PipelineOptions{}.refiner.name, py::arg("settings") = py::none(),
      "A backend with its settings applied, as a dict or keywords (colour=False, share=0.5).");
  m.def(
      "make_completer",
      [](const std::string& name, const py::object& settings, const py::kwargs& kwargs) {
        return std::shared_ptr<Completer>(
            unwrap(completer_registry().make(name, settings_from_python(settings, kwargs))));
      },
      py::arg("name") = PipelineOptions{}.completer.name, py::arg("settings") = py::none(),
      "A backend with its settings applied, as a dict or keywords (colour=False, share=0.5).");
  m.def(
      "make_estimator",
      [](const std::string& name, const py::object& settings, const py::kwargs& kwargs) {
        return std::shared_ptr<PropertyEstimator>(
            unwrap(estimator_registry().make(name, settings_from_python(settings, kwargs))));
      },
      py::arg("name") = PipelineOptions{}.estimator.name, py::arg("settings") = py::none(),
      "A backend with its settings applied, as a dict or keywords (colour=False, share=0.5).");

  // ---- Stages as functions ----
  m.def(
      "make_views", [](const Mesh& mesh, const ViewOptions& options) { return unwrap(make_views(mesh, options)); },
      py::arg("mesh"), py::arg("options") = ViewOptions(), "Cameras around the mesh, each framing it.");
  m.def(
      "render_views",
      [](Renderer& renderer, const Model& model, const std::vector<Camera>& cameras, const RenderOptions& options) {
        py::gil_scoped_release release;
        return unwrap(render_views(renderer, model, cameras, options));
      },
      py::arg("renderer"), py::arg("model"), py::arg("cameras"), py::arg("options") = RenderOptions(),
      py::keep_alive<1, 2>(), "Every camera rendered after renderer.set_model(model).");
  m.def(
      "project",
      [](const Mesh& mesh, const std::vector<View>& views, const std::vector<LabelMap>& maps, int num_classes,
         const ProjectOptions& options) {
        py::gil_scoped_release release;
        if (num_classes <= 0) num_classes = MaterialTable::paper_default().size();
        return unwrap(project(mesh, views, maps, num_classes, options));
      },
      py::arg("mesh"), py::arg("views"), py::arg("label_maps"), py::arg("num_classes") = 0,
      py::arg("options") = ProjectOptions(), "Votes, labels and parts (num_classes 0 = the default table's).");
  m.def(
      "refine",
      [](const Refiner& refiner, const Mesh& mesh, const Projection& projection, const std::vector<View>& views,
         const MaterialTable* table, const py::object& image_decided) {
        std::vector<std::uint8_t> decided;
        if (!image_decided.is_none()) {
          const std::vector<int> faces = int_vector_from_numpy(image_decided, "image_decided");
          if (static_cast<int>(faces.size()) != mesh.num_faces())
            throw py::value_error("image_decided: " + std::to_string(faces.size()) + " values for " +
                                  std::to_string(mesh.num_faces()) + " faces");
          for (const int f : faces) decided.push_back(f != 0 ? 1 : 0);
        }
        RefineInput in{&mesh,
                       &projection.graph,
                       &projection.votes,
                       &projection.labels,
                       &views,
                       &table_or_default(table),
                       image_decided.is_none() ? nullptr : &decided};
        py::gil_scoped_release release;
        return unwrap(refiner.refine(in));
      },
      py::arg("refiner"), py::arg("mesh"), py::arg("projection"), py::arg("views") = std::vector<View>{},
      py::arg("table") = no_table, py::arg("image_decided") = py::none(),
      "Runs a refiner on a projection. image_decided: per face, 1 where the segmenter labelled it from the image "
      "alone (Segmenter.image_decided_faces()); None: not known.");
  m.def(
      "apply_refinement",
      [](const Mesh& mesh, const py::object& labels, Projection& projection, const PartitionOptions& options) {
        const std::vector<int> l = int_vector_from_numpy(labels, "labels");
        py::gil_scoped_release release;
        throw_if_error(apply_refinement(mesh, l, options, projection));
      },
      py::arg("mesh"), py::arg("labels"), py::arg("projection"), py::arg("options") = PartitionOptions(),
      "Puts per-face labels into the projection in place (parts partitioned again).");
  m.def(
      "complete",
      [](const Completer& completer, const Mesh& mesh, const std::vector<Part>& parts, const MaterialTable* table,
         const Completer* fallback) {
        CompletionInput in{&mesh, &parts, &table_or_default(table)};
        py::gil_scoped_release release;
        return unwrap(complete(in, completer, fallback));
      },
      py::arg("completer"), py::arg("mesh"), py::arg("parts"), py::arg("table") = no_table,
      py::arg("fallback") = static_cast<const Completer*>(nullptr),
      "Closes every part; parts the completer fails are redone by `fallback` when given.");
  m.def("part_patch", &part_patch, py::arg("mesh"), py::arg("part"));
  m.def(
      "estimate_properties",
      [](const Mesh& mesh, const std::vector<Part>& parts, const Completion& completion,
         const PropertyEstimator& estimator, const MaterialTable* table, const std::vector<View>& views) {
        py::gil_scoped_release release;
        return unwrap(estimate_properties(mesh, parts, completion, table_or_default(table), estimator, &views));
      },
      py::arg("mesh"), py::arg("parts"), py::arg("completion"), py::arg("estimator"), py::arg("table") = no_table,
      py::arg("views") = std::vector<View>{});
}

}  // namespace g2p::python
