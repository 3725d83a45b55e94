// The data that flows between the stages: cameras and views (render), label
// maps (segment), votes, labels and parts (project), refinements, closed parts
// (complete) and mass properties (properties). Images and per-face arrays are
// numpy copies.
#include "bindings.h"

namespace g2p::python {

namespace {

// A get/set property for an image member: numpy copy out, numpy in.
template <typename Class, typename T>
void image_property(py::class_<Class>& cls, const char* name, Image<T> Class::*member, bool squeeze, int channels,
                    const char* doc) {
  const std::string what = name;
  cls.def_property(
      name, [member, squeeze](const Class& c) { return image_to_numpy(c.*member, squeeze); },
      [member, channels, what](Class& c, const py::object& a) { c.*member = image_from_numpy<T>(a, channels, what); },
      doc);
}

// A get/set property for a std::vector<T> member as a 1-D numpy array.
template <typename Class, typename T>
void vector_property(py::class_<Class>& cls, const char* name, std::vector<T> Class::*member, const char* doc) {
  const std::string what = name;
  cls.def_property(
      name, [member](const Class& c) { return vector_to_numpy(c.*member); },
      [member, what](Class& c, const py::object& a) {
        if constexpr (std::is_same_v<T, int>) {
          c.*member = int_vector_from_numpy(a, what);
        } else {
          auto array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
          if (!array || array.ndim() != 1) throw py::value_error(what + ": expected a 1-D array");
          c.*member = std::vector<T>(array.data(), array.data() + array.size());
        }
      },
      doc);
}

}  // namespace

// Dense (faces, classes) votes; rows of unseen faces are zero.
py::array_t<float> dense_votes(const FaceVotes& votes) {
  const py::ssize_t faces = static_cast<py::ssize_t>(votes.row.size());
  py::array_t<float> out({faces, static_cast<py::ssize_t>(votes.num_classes)});
  float* o = out.mutable_data();
  std::fill(o, o + out.size(), 0.f);
  for (py::ssize_t f = 0; f < faces; ++f)
    if (const float* h = votes.of(static_cast<int>(f))) std::copy(h, h + votes.num_classes, o + f * votes.num_classes);
  return out;
}

void bind_stage_types(py::module_& m) {
  // ---- render ----
  py::class_<Camera>(m, "Camera",
                     "A pinhole or orthographic camera in OpenCV's convention (+z forward, x right, y down).")
      .def(py::init<>())
      .def_static("look_at", &Camera::look_at, py::arg("eye"), py::arg("target"), py::arg("up"), py::arg("width"),
                  py::arg("height"), py::arg("fov_y_deg"))
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height)
      .def_readwrite("orthographic", &Camera::orthographic)
      .def_readwrite("fx", &Camera::fx)
      .def_readwrite("fy", &Camera::fy)
      .def_readwrite("cx", &Camera::cx)
      .def_readwrite("cy", &Camera::cy)
      .def_readwrite("rotation", &Camera::rotation, "world-from-camera; columns are the camera axes")
      .def_readwrite("position", &Camera::position, "metres")
      .def("forward", &Camera::forward)
      .def("intrinsics", &Camera::intrinsics)
      .def("world_to_camera", &Camera::world_to_camera)
      .def("camera_to_world", &Camera::camera_to_world)
      .def(
          "project",
          [](const Camera& c, const Eigen::Vector3d& world) {
            double depth = 0.0;
            Eigen::Vector2d pixel = c.project(world, &depth);
            return py::make_tuple(pixel, depth);
          },
          "(pixel (2,), depth in metres) of a world point")
      .def(
          "ray",
          [](const Camera& c, double px, double py_) {
            Eigen::Vector3d origin, direction;
            c.ray(px, py_, origin, direction);
            return py::make_tuple(origin, direction);
          },
          "(origin, unit direction) through a continuous pixel coordinate")
      .def("validate", [](const Camera& c) { throw_if_error(c.validate()); });

  py::enum_<ViewLayout>(m, "ViewLayout")
      .value("SPHERE", ViewLayout::kSphere)
      .value("FIBONACCI", ViewLayout::kFibonacci)
      .value("TURNTABLE", ViewLayout::kTurntable);
  py::class_<ViewOptions>(m, "ViewOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<ViewOptions>(kw); }))
      .def_readwrite("num_views", &ViewOptions::num_views)
      .def_readwrite("layout", &ViewOptions::layout)
      .def_readwrite("width", &ViewOptions::width, "pixels")
      .def_readwrite("height", &ViewOptions::height, "pixels")
      .def_readwrite("fov_y_deg", &ViewOptions::fov_y_deg)
      .def_readwrite("orthographic", &ViewOptions::orthographic)
      .def_readwrite("margin", &ViewOptions::margin)
      .def_readwrite("elevation_deg", &ViewOptions::elevation_deg);
  py::class_<CameraLight>(m, "CameraLight", "A directional light that turns with the camera")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<CameraLight>(kw); }))
      .def_readwrite("direction", &CameraLight::direction,
                     "towards the light in the camera's frame (x right, y down, z forward)")
      .def_readwrite("irradiance", &CameraLight::irradiance, ">= 0; the studio key light is 2.4");
  m.def("studio_lights", &studio_lights, "libg2p's studio set: key, fill and rim");
  py::class_<RenderOptions>(m, "RenderOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<RenderOptions>(kw); }))
      .def_readwrite("shade", &RenderOptions::shade)
      .def_readwrite("material_buffers", &RenderOptions::material_buffers)
      .def_readwrite("geometry_buffers", &RenderOptions::geometry_buffers)
      .def_readwrite("background", &RenderOptions::background, "sRGB (r, g, b)")
      .def_readwrite("max_layers", &RenderOptions::max_layers)
      .def_readwrite("tile_size", &RenderOptions::tile_size)
      .def_readwrite("lights", &RenderOptions::lights, "CameraLight list; empty: studio_lights()");

  py::class_<View> view(m, "View",
                        "One rendered view. Buffers are numpy copies (None when not rendered): rgb (H, W, 3) "
                        "uint8, face_id (H, W) int32 (-1 = background), depth (H, W) float32, normal (H, W, 3), "
                        "base_color (H, W, 4), metallic_roughness (H, W, 2), transmission (H, W).");
  view.def(py::init<>()).def_readwrite("camera", &View::camera);
  image_property(view, "face_id", &View::face_id, true, 1, "(H, W) int32 triangle index, -1 = background");
  image_property(view, "rgb", &View::rgb, false, 3, "(H, W, 3) uint8 sRGB");
  image_property(view, "depth", &View::depth, true, 1, "(H, W) float32 metres along +z, inf = background");
  image_property(view, "normal", &View::normal, false, 3, "(H, W, 3) float32 world-space unit normals");
  image_property(view, "base_color", &View::base_color, false, 4, "(H, W, 4) float32 linear RGBA");
  image_property(view, "metallic_roughness", &View::metallic_roughness, false, 2, "(H, W, 2) float32");
  image_property(view, "transmission", &View::transmission, true, 1, "(H, W) float32");
  view.def_property_readonly("width", [](const View& v) { return v.camera.width; })
      .def_property_readonly("height", [](const View& v) { return v.camera.height; })
      .def("__repr__", [](const View& v) {
        return "<g2p.View " + std::to_string(v.camera.width) + "x" + std::to_string(v.camera.height) + ">";
      });

  // ---- segment ----
  py::class_<LabelMap> label_map(m, "LabelMap", "Per-pixel material classes of one view.");
  label_map.def(py::init([](const py::object& labels, const py::object& probabilities) {
                  LabelMap map;
                  map.labels = image_from_numpy<std::int32_t>(labels, 1, "labels");
                  map.probabilities = image_from_numpy<float>(probabilities, 0, "probabilities");
                  return map;
                }),
                py::arg("labels") = py::none(), py::arg("probabilities") = py::none());
  image_property(label_map, "labels", &LabelMap::labels, true, 1, "(H, W) int32 class per pixel, -1 = unknown");
  image_property(label_map, "probabilities", &LabelMap::probabilities, false, 0,
                 "(H, W, C) float32 class probabilities, or None");
  m.def(
      "colorize_labels",
      [](const py::object& labels, const MaterialTable& table, std::array<std::uint8_t, 3> background) {
        return image_to_numpy(colorize_labels(image_from_numpy<std::int32_t>(labels, 1, "labels"), table, background),
                              false);
      },
      py::arg("labels"), py::arg("table") = MaterialTable::paper_default(),
      py::arg("background") = std::array<std::uint8_t, 3>{0, 0, 0}, "(H, W) labels as (H, W, 3) uint8 colours");

  // ---- project ----
  py::class_<FaceGraph>(m, "FaceGraph", "Faces sharing an edge after welding, compressed rows.")
      .def_property_readonly("offsets", [](const FaceGraph& g) { return vector_to_numpy(g.offsets); })
      .def_property_readonly("neighbors", [](const FaceGraph& g) { return vector_to_numpy(g.neighbors); })
      .def_property_readonly("shared_edge_m", [](const FaceGraph& g) { return vector_to_numpy(g.shared_edge_m); })
      .def_property_readonly("welded_vertex", [](const FaceGraph& g) { return vector_to_numpy(g.welded_vertex); })
      .def_property_readonly("num_faces", &FaceGraph::num_faces)
      .def("neighbors_of", [](const FaceGraph& g, int face) {
        if (face < 0 || face >= g.num_faces()) throw py::index_error("face " + std::to_string(face));
        return std::vector<int>(g.neighbors.begin() + g.offsets[face], g.neighbors.begin() + g.offsets[face + 1]);
      });
  py::enum_<VoteMode>(m, "VoteMode").value("HARD", VoteMode::kHard).value("SOFT", VoteMode::kSoft);
  py::class_<VoteOptions>(m, "VoteOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<VoteOptions>(kw); }))
      .def_readwrite("mode", &VoteOptions::mode)
      .def_readwrite("weight_by_angle", &VoteOptions::weight_by_angle)
      .def_readwrite("weight_by_footprint", &VoteOptions::weight_by_footprint);
  py::class_<FaceVotes>(m, "FaceVotes")
      .def_readonly("num_classes", &FaceVotes::num_classes)
      .def_property_readonly("total", [](const FaceVotes& v) { return vector_to_numpy(v.total); })
      .def("dense", &dense_votes, "(faces, classes) float32 vote histograms; zero rows for unseen faces");
  py::class_<FaceLabels> face_labels(m, "FaceLabels");
  vector_property(face_labels, "label", &FaceLabels::label, "(M,) class per face");
  vector_property(face_labels, "confidence", &FaceLabels::confidence, "(M,) the winner's share of the votes");
  vector_property(face_labels, "seen", &FaceLabels::seen, "(M,) 1 if a view voted for the face");
  py::class_<Part> part(m, "Part", "Connected faces of one material class.");
  part.def(py::init([](int label, const py::object& faces, double area_m2) {
             Part p;
             p.label = label;
             p.faces = int_vector_from_numpy(faces, "faces");
             p.area_m2 = area_m2;
             return p;
           }),
           py::arg("label"), py::arg("faces"), py::arg("area_m2") = 0.0)
      .def_readwrite("label", &Part::label)
      .def_readwrite("area_m2", &Part::area_m2);
  vector_property(part, "faces", &Part::faces, "(K,) int32 indices into Mesh.triangles");
  part.def("__repr__", [](const Part& p) {
    return "<g2p.Part label " + std::to_string(p.label) + ", " + std::to_string(p.faces.size()) + " faces>";
  });
  py::class_<PartitionOptions>(m, "PartitionOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<PartitionOptions>(kw); }))
      .def_readwrite("min_part_area_fraction", &PartitionOptions::min_part_area_fraction)
      .def_readwrite("merge_max_confidence", &PartitionOptions::merge_max_confidence);
  py::class_<ProjectOptions>(m, "ProjectOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<ProjectOptions>(kw); }))
      .def_readwrite("vote", &ProjectOptions::vote)
      .def_readwrite("weld_tolerance", &ProjectOptions::weld_tolerance)
      .def_readwrite("partition", &ProjectOptions::partition);
  py::class_<Projection> projection(m, "Projection", "The project stage's result.");
  projection.def_readonly("graph", &Projection::graph)
      .def_readonly("votes", &Projection::votes)
      .def_readonly("labels", &Projection::labels)
      .def_readonly("parts", &Projection::parts);
  vector_property(projection, "face_part", &Projection::face_part, "(M,) part index per face");

  // ---- refine ----
  py::class_<LabelChange>(m, "LabelChange")
      .def(py::init([](int face, int from, int to, std::string reason) {
             return LabelChange{face, from, to, std::move(reason)};
           }),
           py::arg("face"), py::arg("from_label"), py::arg("to_label"), py::arg("reason") = "")
      .def_readwrite("face", &LabelChange::face)
      .def_readwrite("from_label", &LabelChange::from)
      .def_readwrite("to_label", &LabelChange::to)
      .def_readwrite("reason", &LabelChange::reason);
  py::class_<RefineResult> refine_result(m, "RefineResult");
  refine_result.def(py::init([](const py::kwargs& kw) { return from_kwargs<RefineResult>(kw); }));
  vector_property(refine_result, "labels", &RefineResult::labels, "(M,) class per face");
  refine_result.def_readwrite("changes", &RefineResult::changes)
      .def_readwrite("notes", &RefineResult::notes)
      .def_readwrite("fell_back", &RefineResult::fell_back);

  // ---- complete ----
  py::class_<MeshChecks>(m, "MeshChecks")
      .def_readonly("closed", &MeshChecks::closed)
      .def_readonly("manifold", &MeshChecks::manifold)
      .def_readonly("outward", &MeshChecks::outward)
      .def_readonly("self_intersection_free", &MeshChecks::self_intersection_free)
      .def_readonly("self_intersections_checked", &MeshChecks::self_intersections_checked)
      .def_readonly("num_components", &MeshChecks::num_components)
      .def_readonly("num_self_intersections", &MeshChecks::num_self_intersections)
      .def_readonly("volume_m3", &MeshChecks::volume_m3)
      .def_readonly("area_m2", &MeshChecks::area_m2)
      .def_readonly("max_distance_m", &MeshChecks::max_distance_m)
      .def_readonly("relative_distance", &MeshChecks::relative_distance)
      .def_property_readonly("watertight", &MeshChecks::watertight);
  m.def(
      "check_closed_mesh",
      [](const Mesh& mesh, const Mesh* patch) {
        py::gil_scoped_release release;
        return check_closed_mesh(mesh, patch);
      },
      py::arg("mesh"), py::arg("patch") = nullptr);
  py::class_<CompletedPart>(m, "CompletedPart", "One part closed into a watertight volume.")
      .def(py::init<>())
      .def_readwrite("part", &CompletedPart::part)
      .def_readwrite("label", &CompletedPart::label)
      .def_readwrite("mesh", &CompletedPart::mesh, "the closed mesh")
      .def_readwrite("checks", &CompletedPart::checks)
      .def_readwrite("backend", &CompletedPart::backend)
      .def_readwrite("notes", &CompletedPart::notes)
      .def_readwrite("ok", &CompletedPart::ok)
      .def_property_readonly("volume_m3", [](const CompletedPart& c) { return c.checks.volume_m3; });
  py::class_<Completion>(m, "Completion")
      .def(py::init<>())
      .def_readwrite("parts", &Completion::parts)
      .def_readwrite("object_volume_m3", &Completion::object_volume_m3)
      .def_readwrite("parts_volume_m3", &Completion::parts_volume_m3)
      .def_readwrite("grid_spacing_m", &Completion::grid_spacing_m)
      .def_readwrite("notes", &Completion::notes);

  // ---- properties ----
  py::class_<MassProperties>(m, "MassProperties")
      .def(py::init<>())
      .def_readwrite("mass_kg", &MassProperties::mass_kg)
      .def_readwrite("volume_m3", &MassProperties::volume_m3)
      .def_readwrite("area_m2", &MassProperties::area_m2)
      .def_readwrite("center_of_mass", &MassProperties::center_of_mass, "(3,) metres")
      .def_readwrite("inertia", &MassProperties::inertia, "(3, 3) kg m^2 about the centre of mass")
      .def("principal_moments", &MassProperties::principal_moments)
      .def("principal_axes", &MassProperties::principal_axes);
  m.def("solid_mass_properties",
        [](const Mesh& mesh, double density_kg_m3) { return unwrap(solid_mass_properties(mesh, density_kg_m3)); });
  m.def("shell_mass_properties", [](const Mesh& mesh, double density_kg_m3, double thickness_m) {
    return unwrap(shell_mass_properties(mesh, density_kg_m3, thickness_m));
  });
  m.def(
      "fill_mass_properties",
      [](const Mesh& closed, double density_kg_m3, double volume_m3) {
        return unwrap(fill_mass_properties(closed, density_kg_m3, volume_m3));
      },
      "A fill of volume_m3 settled in the bottom of a closed mesh (gravity along -Z).");
  m.def("combine", &combine, "Several parts' mass properties as one body.");
  py::class_<WallMeasurement>(m, "WallMeasurement")
      .def_readonly("rays", &WallMeasurement::rays)
      .def_readonly("inner_hits", &WallMeasurement::inner_hits)
      .def_readonly("thickness_m", &WallMeasurement::thickness_m)
      .def_readonly("inner_wall_m", &WallMeasurement::inner_wall_m)
      .def_property_readonly("inner_fraction", &WallMeasurement::inner_fraction);
  py::class_<PartProperties>(m, "PartProperties",
                             "What an estimator says about one part. Keyword construction: "
                             "g2p.PartProperties(label=5, density_kg_m3=7850.0, structure=g2p.Structure.SOLID).")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<PartProperties>(kw); }))
      .def_readwrite("label", &PartProperties::label)
      .def_readwrite("density_kg_m3", &PartProperties::density_kg_m3)
      .def_readwrite("density_min_kg_m3", &PartProperties::density_min_kg_m3)
      .def_readwrite("density_max_kg_m3", &PartProperties::density_max_kg_m3)
      .def_readwrite("structure", &PartProperties::structure)
      .def_readwrite("wall_thickness_m", &PartProperties::wall_thickness_m)
      .def_readwrite("double_walled", &PartProperties::double_walled)
      .def_readwrite("contents_density_kg_m3", &PartProperties::contents_density_kg_m3)
      .def_readwrite("contents_fill", &PartProperties::contents_fill, "share of a hollow part's cavity, 0 to 1")
      .def_readwrite("friction_static", &PartProperties::friction_static)
      .def_readwrite("friction_dynamic", &PartProperties::friction_dynamic)
      .def_readwrite("restitution", &PartProperties::restitution)
      .def_readwrite("solref", &PartProperties::solref)
      .def_readwrite("solimp", &PartProperties::solimp)
      .def_readwrite("density_source", &PartProperties::density_source)
      .def_readwrite("structure_source", &PartProperties::structure_source)
      .def_readwrite("thickness_source", &PartProperties::thickness_source)
      .def_readwrite("contact_source", &PartProperties::contact_source)
      .def_readwrite("walls", &PartProperties::walls)
      .def_readwrite("notes", &PartProperties::notes);
  py::class_<PartReport>(m, "PartReport")
      .def_readonly("part", &PartReport::part)
      .def_readonly("properties", &PartReport::properties)
      .def_readonly("mass", &PartReport::mass, "the walls and the contents together")
      .def_readonly("contents", &PartReport::contents, "the contents alone (zero mass when empty)")
      .def_readonly("mass_min_kg", &PartReport::mass_min_kg)
      .def_readonly("mass_max_kg", &PartReport::mass_max_kg)
      .def_readonly("mass_median_kg", &PartReport::mass_median_kg,
                    "the mass posterior (the kind's or bulk density's); 0 = not judged")
      .def_readonly("mass_p05_kg", &PartReport::mass_p05_kg)
      .def_readonly("mass_p95_kg", &PartReport::mass_p95_kg)
      .def_readonly("completed_ok", &PartReport::completed_ok);
  py::class_<PropertiesReport>(m, "PropertiesReport")
      .def_readonly("parts", &PropertiesReport::parts)
      .def_readonly("object", &PropertiesReport::object, "all parts combined")
      .def_readonly("mass_min_kg", &PropertiesReport::mass_min_kg)
      .def_readonly("mass_max_kg", &PropertiesReport::mass_max_kg)
      .def_readonly("mass_median_kg", &PropertiesReport::mass_median_kg,
                    "the mass posterior's median; 0 = not judged (docs/properties.md)")
      .def_readonly("mass_p05_kg", &PropertiesReport::mass_p05_kg)
      .def_readonly("mass_p95_kg", &PropertiesReport::mass_p95_kg)
      .def_readonly("mass_judged_by", &PropertiesReport::mass_judged_by,
                    "what the interval was judged by, in words; '' = not judged")
      .def_property_readonly(
          "kind_range_kg",
          [](const PropertiesReport& r) { return py::make_tuple(r.kind_range_kg[0], r.kind_range_kg[1]); })
      .def_readonly("notes", &PropertiesReport::notes)
      .def(
          "to_json",
          [](const PropertiesReport& r, const MaterialTable& table) {
            return py::module_::import("json").attr("loads")(report_json(r, table));
          },
          py::arg("table") = MaterialTable::paper_default(), "report.json (docs/report-schema.md) as a dict");
}

}  // namespace g2p::python
