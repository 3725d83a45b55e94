// The decompose stage in Python: options, results, the Decomposer interface
// (subclassable), the registry and the stage's functions.
#include "bindings.h"

namespace g2p::python {

namespace {

// A Python Decomposer: decompose(self, closed: g2p.Mesh, options) returns a
// list of hulls, each a g2p.Mesh or an (N, 3) array of points whose convex
// hull libg2p takes (within the vertex budget).
class PyDecomposer : public Decomposer {
 public:
  Status configure(const BackendSettings& settings) override {
    py::gil_scoped_acquire gil;
    try {
      py::function f = py::get_override(static_cast<const Decomposer*>(this), "configure");
      if (!f) return Decomposer::configure(settings);
      f(settings);
      return Status::Ok();
    } catch (const py::error_already_set& e) {
      return status_from_python(e, python_class_name(this) + ".configure");
    }
  }
  Status decompose(const Mesh& closed, const DecomposeOptions& options, ConvexDecomposition& out) const override {
    py::gil_scoped_acquire gil;
    const std::string where = python_class_name(this) + ".decompose";
    try {
      py::function f = py::get_override(static_cast<const Decomposer*>(this), "decompose");
      if (!f) return Status::Unsupported(where + " is not defined");
      py::object returned = f(closed, options);
      if (!py::isinstance<py::sequence>(returned))
        return Status::Internal(where + ": expected a list of hulls (g2p.Mesh or (N, 3) point arrays)");
      for (const py::handle item : py::reinterpret_borrow<py::sequence>(returned)) {
        if (py::isinstance<Mesh>(item)) {
          out.hulls.push_back(item.cast<Mesh>());
          continue;
        }
        std::vector<Eigen::Vector3d> points = rows_from_numpy<Eigen::Vector3d>(item, where + ": a hull's points");
        Result<Mesh> hull = convex_hull(points, options.max_vertices_per_hull);
        if (!hull.ok()) return hull.status().with_context(where);
        out.hulls.push_back(std::move(*hull));
      }
      return Status::Ok();
    } catch (const py::error_already_set& e) {
      return status_from_python(e, where);
    }
  }
};

}  // namespace

void bind_decompose(py::module_& m) {
  py::class_<DecomposeOptions>(m, "DecomposeOptions",
                               "What every decomposer honours: hulls per part, vertices per hull, the depth of "
                               "concavities left alone (m; 0: 1 % of the object's diagonal in the pipeline).")
      .def(py::init(&from_kwargs<DecomposeOptions>))
      .def_readwrite("max_hulls", &DecomposeOptions::max_hulls)
      .def_readwrite("max_vertices_per_hull", &DecomposeOptions::max_vertices_per_hull)
      .def_readwrite("min_depth_m", &DecomposeOptions::min_depth_m)
      .def_readwrite("measure_resolution", &DecomposeOptions::measure_resolution)
      .def_readwrite("coverage_tolerance", &DecomposeOptions::coverage_tolerance)
      .def_readwrite("max_hulls_per_object", &DecomposeOptions::max_hulls_per_object);

  py::class_<ConvexDecomposition>(m, "ConvexDecomposition", "One part's collision geometry: convex hulls.")
      .def(py::init<>())
      .def_readwrite("hulls", &ConvexDecomposition::hulls,
                     "list of g2p.Mesh, each closed and convex (a copy: assign a new list to change it)")
      .def_readwrite("backend", &ConvexDecomposition::backend)
      .def_readwrite("fell_back", &ConvexDecomposition::fell_back)
      .def_readwrite("part_volume_m3", &ConvexDecomposition::part_volume_m3)
      .def_readwrite("hulls_volume_m3", &ConvexDecomposition::hulls_volume_m3)
      .def_readwrite("mean_distance_m", &ConvexDecomposition::mean_distance_m)
      .def_readwrite("max_distance_m", &ConvexDecomposition::max_distance_m)
      .def_readwrite("uncovered_mean_m", &ConvexDecomposition::uncovered_mean_m)
      .def_readwrite("uncovered_max_m", &ConvexDecomposition::uncovered_max_m)
      .def_readwrite("hull_budget", &ConvexDecomposition::hull_budget)
      .def_readwrite("coverage_tolerance_m", &ConvexDecomposition::coverage_tolerance_m)
      .def_readwrite("seconds", &ConvexDecomposition::seconds)
      .def_readwrite("notes", &ConvexDecomposition::notes)
      .def("__repr__", [](const ConvexDecomposition& d) {
        return "<g2p.ConvexDecomposition " + std::to_string(d.hulls.size()) + " hulls, " + d.backend + ">";
      });

  py::class_<Decomposer, PyDecomposer, std::shared_ptr<Decomposer>>(
      m, "Decomposer",
      "The decompose stage. Subclass it: decompose(self, closed: g2p.Mesh, options: g2p.DecomposeOptions) returns "
      "a list of hulls, each a g2p.Mesh or an (N, 3) array of points (libg2p takes their convex hull). "
      "decompose_part checks the result and falls back to the part's single hull when it is invalid or raises.")
      .def(py::init<>())
      .def(
          "settings", [](Decomposer& d) { return settings_to_python(d.settings().info()); },
          "Its settings with their current values: a list of dicts (key, type, unit, range, value, help).")
      .def("configure", [](Decomposer& d, const BackendSettings& settings) { throw_if_error(d.configure(settings)); })
      .def(
          "decompose",
          [](const Decomposer& d, const Mesh& closed, const DecomposeOptions& options) {
            ConvexDecomposition out;
            {
              py::gil_scoped_release release;
              throw_if_error(d.decompose(closed, options, out));
            }
            return out.hulls;
          },
          py::arg("closed"), py::arg("options") = DecomposeOptions{});

  m.def("decomposer_names", []() { return decomposer_registry().names(); });
  m.def(
      "make_decomposer",
      [](const std::string& name, const py::object& settings, const py::kwargs& kwargs) {
        return std::shared_ptr<Decomposer>(
            unwrap(decomposer_registry().make(name, settings_from_python(settings, kwargs))));
      },
      py::arg("name") = PipelineOptions{}.decomposer.name, py::arg("settings") = py::none(),
      "A decomposer with its settings applied, as a dict or keywords (resolution=96).");
  m.def(
      "decompose_part",
      [](const Mesh& closed, const Decomposer& decomposer, const DecomposeOptions& options) {
        py::gil_scoped_release release;
        return unwrap(decompose_part(closed, decomposer, options));
      },
      py::arg("closed"), py::arg("decomposer"), py::arg("options") = DecomposeOptions{},
      "One part's convex decomposition, checked (fallback: its single hull) and measured.");
  m.def(
      "convex_hull",
      [](const py::object& points, int max_vertices) {
        std::vector<Eigen::Vector3d> p = rows_from_numpy<Eigen::Vector3d>(points, "points");
        return unwrap(convex_hull(p, max_vertices));
      },
      py::arg("points"), py::arg("max_vertices") = 0,
      "The convex hull of an (N, 3) array as a closed g2p.Mesh; max_vertices > 0 caps its vertices.");
  m.def("enclosed_volume", &enclosed_volume, py::arg("mesh"), "Volume of a closed, outward mesh, m^3.");
}

}  // namespace g2p::python
