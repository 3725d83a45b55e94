// Core types: Mesh and Model (arrays as numpy copies), the material
// vocabulary, and reading and writing models.
#include "bindings.h"

namespace g2p::python {

namespace {

// A model built from arrays, with the provenance load_model would give a
// single-mesh file: face i is face i of source mesh 0.
Model model_from_arrays(const py::handle& positions, const py::handle& triangles, const py::handle& normals,
                        const py::handle& uvs, const py::handle& face_materials,
                        const std::vector<std::string>& material_names, const std::string& name) {
  Model model;
  Mesh& mesh = model.mesh;
  mesh.positions = rows_from_numpy<Eigen::Vector3f>(positions, "positions");
  mesh.triangles = rows_from_numpy<Eigen::Vector3i>(triangles, "triangles");
  mesh.normals = rows_from_numpy<Eigen::Vector3f>(normals, "normals");
  mesh.uvs = rows_from_numpy<Eigen::Vector2f>(uvs, "uvs");
  std::vector<int> materials;
  if (!face_materials.is_none()) {
    materials = int_vector_from_numpy(face_materials, "face_materials");
    if (materials.size() != mesh.triangles.size())
      throw py::value_error("face_materials: expected one entry per triangle (" +
                            std::to_string(mesh.triangles.size()) + "), got " + std::to_string(materials.size()));
  }
  int num_materials = static_cast<int>(material_names.size());
  for (int m : materials) num_materials = std::max(num_materials, m + 1);
  for (int m = 0; m < num_materials; ++m) {
    SourceMaterial material;
    material.name = m < static_cast<int>(material_names.size()) ? material_names[m] : "material_" + std::to_string(m);
    model.materials.push_back(std::move(material));
  }
  mesh.face_source.resize(mesh.triangles.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    int material = materials.empty() ? (num_materials > 0 ? 0 : -1) : materials[f];
    mesh.face_source[f] = FaceSource{0, static_cast<std::int32_t>(f), material};
  }
  throw_if_error(validate(mesh));
  model.info.path = name;
  model.info.format = "arrays";
  model.info.up_axis = 'Z';
  model.info.num_source_meshes = 1;
  model.info.num_degenerate_faces = flag_degenerate_faces(mesh);
  if (mesh.normals.empty()) compute_vertex_normals(mesh);
  SourcePrimitive primitive;
  primitive.mesh_name = primitive.node_name = name;
  primitive.mesh = 0;
  primitive.material = num_materials > 0 ? 0 : -1;
  primitive.num_faces = mesh.num_faces();
  primitive.num_vertices = mesh.num_vertices();
  model.primitives.push_back(primitive);
  return model;
}

ImportOptions import_options(const py::object& options, const py::kwargs& kwargs) {
  if (!options.is_none() && kwargs.size() > 0)
    throw py::type_error("load_model: give either options= or keyword options, not both");
  if (!options.is_none()) return options.cast<ImportOptions>();
  return from_kwargs<ImportOptions>(kwargs);
}

py::array_t<std::int32_t> face_source_array(const Mesh& mesh) {
  py::array_t<std::int32_t> out({static_cast<py::ssize_t>(mesh.face_source.size()), py::ssize_t{3}});
  std::int32_t* o = out.mutable_data();
  for (const FaceSource& s : mesh.face_source) *o++ = s.mesh, *o++ = s.face, *o++ = s.material;
  return out;
}

// One value as --set writes it.
std::string setting_text(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "on" : "off";
  if (py::isinstance<py::float_>(v)) return py::str(py::repr(v));  // shortest round trip
  return py::str(v);
}

}  // namespace

BackendSettings settings_from_python(const py::handle& settings, const py::kwargs& kwargs) {
  BackendSettings out;
  if (!settings.is_none()) {
    if (py::isinstance<BackendSettings>(settings)) {
      out = settings.cast<BackendSettings>();
    } else if (py::isinstance<py::dict>(settings)) {
      for (const auto& item : settings.cast<py::dict>()) out[py::str(item.first)] = setting_text(item.second);
    } else {
      throw py::type_error("settings must be a dict of KEY: VALUE");
    }
  }
  for (const auto& item : kwargs) out[py::str(item.first)] = setting_text(item.second);
  return out;
}

py::list settings_to_python(const std::vector<SettingInfo>& info) {
  py::list out;
  for (const SettingInfo& i : info)
    out.append(py::dict(py::arg("key") = i.key, py::arg("type") = i.type, py::arg("unit") = i.unit,
                        py::arg("range") = i.range, py::arg("value") = i.value, py::arg("help") = i.help));
  return out;
}

void bind_core(py::module_& m) {
  // Settings edited in place; a dict converts implicitly where a function takes them.
  py::bind_map<BackendSettings>(m, "BackendSettings", "Backend settings, KEY -> VALUE strings.")
      .def(py::init([](const py::dict& d) { return settings_from_python(d, py::kwargs()); }));
  py::implicitly_convertible<py::dict, BackendSettings>();

  py::enum_<Structure>(m, "Structure")
      .value("SOLID", Structure::kSolid)
      .value("HOLLOW", Structure::kHollow)
      .def("__str__", [](Structure s) { return to_string(s); });
  py::enum_<ValueSource>(m, "ValueSource")
      .value("TABLE", ValueSource::kTable)
      .value("GEOMETRY", ValueSource::kGeometry)
      .value("VLM", ValueSource::kVlm)
      .value("USER", ValueSource::kUser)
      .value("KIND", ValueSource::kKind)
      .def("__str__", [](ValueSource s) { return to_string(s); });
  py::enum_<UpAxis>(m, "UpAxis")
      .value("AUTO", UpAxis::kAuto)
      .value("X", UpAxis::kX)
      .value("Y", UpAxis::kY)
      .value("Z", UpAxis::kZ);
  py::enum_<AlphaMode>(m, "AlphaMode")
      .value("OPAQUE", AlphaMode::kOpaque)
      .value("MASK", AlphaMode::kMask)
      .value("BLEND", AlphaMode::kBlend);

  // ---- Mesh ----
  py::class_<Mesh>(m, "Mesh",
                   "A triangle mesh in metres (+Z up). Array attributes are numpy copies: assign a whole array to "
                   "change one (mesh.positions = p), in-place edits of a returned array do not reach the mesh.")
      .def(py::init([](const py::object& positions, const py::object& triangles) {
             Mesh mesh;
             mesh.positions = rows_from_numpy<Eigen::Vector3f>(positions, "positions");
             mesh.triangles = rows_from_numpy<Eigen::Vector3i>(triangles, "triangles");
             return mesh;
           }),
           py::arg("positions") = py::none(), py::arg("triangles") = py::none())
      .def_property(
          "positions", [](const Mesh& mesh) { return rows_to_numpy<double>(mesh.positions); },
          [](Mesh& mesh, const py::object& a) { mesh.positions = rows_from_numpy<Eigen::Vector3f>(a, "positions"); },
          "(N, 3) float64 vertex positions in metres (stored as float32)")
      .def_property(
          "triangles", [](const Mesh& mesh) { return rows_to_numpy<std::int32_t>(mesh.triangles); },
          [](Mesh& mesh, const py::object& a) { mesh.triangles = rows_from_numpy<Eigen::Vector3i>(a, "triangles"); },
          "(M, 3) int32 vertex indices, counter-clockwise seen from outside")
      .def_property(
          "normals", [](const Mesh& mesh) { return rows_to_numpy<double>(mesh.normals); },
          [](Mesh& mesh, const py::object& a) { mesh.normals = rows_from_numpy<Eigen::Vector3f>(a, "normals"); },
          "(N, 3) per-vertex unit normals, or (0, 3)")
      .def_property(
          "uvs", [](const Mesh& mesh) { return rows_to_numpy<double>(mesh.uvs); },
          [](Mesh& mesh, const py::object& a) { mesh.uvs = rows_from_numpy<Eigen::Vector2f>(a, "uvs"); },
          "(N, 2) texture coordinates (v down, as glTF), or (0, 2)")
      .def_property_readonly("face_source", &face_source_array,
                             "(M, 3) int32: source mesh, source face and source material of each triangle")
      .def_property_readonly("face_flags", [](const Mesh& mesh) { return vector_to_numpy(mesh.face_flags); })
      .def_property_readonly("num_vertices", &Mesh::num_vertices)
      .def_property_readonly("num_faces", &Mesh::num_faces)
      .def(
          "bounds",
          [](const Mesh& mesh) {
            const Eigen::AlignedBox3d box = bounds(mesh);
            return py::make_tuple(Eigen::Vector3d(box.min()), Eigen::Vector3d(box.max()));
          },
          "(min, max) corners of the axis-aligned bounding box")
      .def("face_area",
           [](const Mesh& mesh, int face) {
             if (face < 0 || face >= mesh.num_faces()) throw py::index_error("face " + std::to_string(face));
             return face_area(mesh, face);
           })
      .def(
          "surface_area", [](const Mesh& mesh) { return surface_area(mesh); }, "m^2")
      .def("compute_vertex_normals", [](Mesh& mesh) { compute_vertex_normals(mesh); })
      .def(
          "validate", [](const Mesh& mesh) { throw_if_error(validate(mesh)); },
          "Raises g2p.Error naming the first inconsistent vertex or face.")
      .def("__repr__", [](const Mesh& mesh) {
        return "<g2p.Mesh " + std::to_string(mesh.num_vertices()) + " vertices, " + std::to_string(mesh.num_faces()) +
               " faces>";
      });

  // ---- Model ----
  py::enum_<WrapMode>(m, "WrapMode")
      .value("REPEAT", WrapMode::kRepeat)
      .value("CLAMP_TO_EDGE", WrapMode::kClampToEdge)
      .value("MIRRORED_REPEAT", WrapMode::kMirroredRepeat);
  py::class_<Texture>(m, "Texture")
      .def_readonly("uri", &Texture::uri)
      .def_readonly("uv_set", &Texture::uv_set, "the UV set it reads: 0 = Mesh.uvs, 1 = the second set")
      .def_property_readonly("empty", &Texture::empty)
      .def_property_readonly(
          "image",
          [](const Texture& t) -> py::object { return t.image ? image_to_numpy(*t.image, false) : py::none(); },
          "(H, W, 4) uint8 RGBA, or None");
  py::class_<SourceMaterial>(m, "SourceMaterial")
      .def_readonly("name", &SourceMaterial::name)
      .def_readonly("base_color", &SourceMaterial::base_color, "linear RGBA factor")
      .def_readonly("metallic", &SourceMaterial::metallic)
      .def_readonly("roughness", &SourceMaterial::roughness)
      .def_readonly("alpha_mode", &SourceMaterial::alpha_mode)
      .def_readonly("alpha_cutoff", &SourceMaterial::alpha_cutoff)
      .def_readonly("transmission", &SourceMaterial::transmission)
      .def_readonly("emissive", &SourceMaterial::emissive)
      .def_readonly("double_sided", &SourceMaterial::double_sided)
      .def_readonly("base_color_texture", &SourceMaterial::base_color_texture)
      .def_readonly("metallic_roughness_texture", &SourceMaterial::metallic_roughness_texture)
      .def_readonly("normal_texture", &SourceMaterial::normal_texture)
      .def_readonly("normal_scale", &SourceMaterial::normal_scale)
      .def_readonly("occlusion_texture", &SourceMaterial::occlusion_texture)
      .def_readonly("occlusion_strength", &SourceMaterial::occlusion_strength)
      .def_readonly("emissive_texture", &SourceMaterial::emissive_texture)
      .def_readonly("pbr_from_file", &SourceMaterial::pbr_from_file,
                    "False for formats without PBR materials (OBJ, PLY, STL, DAE): metallic and roughness derived")
      .def("__repr__", [](const SourceMaterial& s) { return "<g2p.SourceMaterial '" + s.name + "'>"; });
  py::class_<SourcePrimitive>(m, "SourcePrimitive")
      .def_readonly("mesh_name", &SourcePrimitive::mesh_name)
      .def_readonly("node_name", &SourcePrimitive::node_name)
      .def_readonly("mesh", &SourcePrimitive::mesh)
      .def_readonly("material", &SourcePrimitive::material)
      .def_readonly("first_face", &SourcePrimitive::first_face)
      .def_readonly("num_faces", &SourcePrimitive::num_faces)
      .def_readonly("first_vertex", &SourcePrimitive::first_vertex)
      .def_readonly("num_vertices", &SourcePrimitive::num_vertices);
  py::class_<ImportInfo>(m, "ImportInfo")
      .def_readonly("path", &ImportInfo::path)
      .def_readonly("format", &ImportInfo::format)
      .def_readonly("unit_scale_m", &ImportInfo::unit_scale_m)
      .def_readonly("scale_source", &ImportInfo::scale_source)
      .def_readonly("looks_normalised", &ImportInfo::looks_normalised)
      .def_property_readonly("up_axis", [](const ImportInfo& i) { return std::string(1, i.up_axis); })
      .def_readonly("file_to_model", &ImportInfo::file_to_model)
      .def_readonly("num_source_meshes", &ImportInfo::num_source_meshes)
      .def_readonly("num_degenerate_faces", &ImportInfo::num_degenerate_faces)
      .def_readonly("num_skipped_primitives", &ImportInfo::num_skipped_primitives)
      .def_readonly("warnings", &ImportInfo::warnings);
  py::class_<Model>(m, "Model", "An imported asset: one merged Mesh, its source materials and the import record.")
      .def(py::init<>())
      .def_static("from_arrays", &model_from_arrays, py::arg("positions"), py::arg("triangles"),
                  py::arg("normals") = py::none(), py::arg("uvs") = py::none(), py::arg("face_materials") = py::none(),
                  py::arg("material_names") = std::vector<std::string>{}, py::arg("name") = "object",
                  "A model from numpy arrays: positions (N, 3) in metres, +Z up; triangles (M, 3); optional "
                  "per-vertex normals and uvs, per-face material indices and material names (which the default "
                  "segmenter reads). `name` becomes the asset name. Raises g2p.InvalidArgumentError for "
                  "inconsistent arrays.")
      .def_readwrite("mesh", &Model::mesh)
      .def_readonly("materials", &Model::materials)
      .def_readonly("primitives", &Model::primitives)
      .def_readonly("info", &Model::info)
      .def_property_readonly("num_faces", [](const Model& model) { return model.mesh.num_faces(); })
      .def_property_readonly("num_vertices", [](const Model& model) { return model.mesh.num_vertices(); })
      .def_property_readonly("material_names",
                             [](const Model& model) {
                               std::vector<std::string> names;
                               for (const SourceMaterial& s : model.materials) names.push_back(s.name);
                               return names;
                             })
      .def("material_name",
           [](const Model& model, int face) {
             if (face < 0 || face >= model.mesh.num_faces()) throw py::index_error("face " + std::to_string(face));
             return model.material_name(face);
           })
      .def("summary", &model_summary_text, "what `g2p info` prints: frame, faces, bounds, materials, warnings")
      .def(
          "summary_json",
          [](const Model& model) { return py::module_::import("json").attr("loads")(model_summary_json(model)); },
          "what `g2p info --json` prints, as a dict")
      .def("anonymize_names", [](Model& model) { anonymize_names(model); })
      .def("reduce_to_base_color", [](Model& model) { reduce_to_base_color(model); })
      .def("__repr__", [](const Model& model) {
        return "<g2p.Model '" + model.info.path + "' " + std::to_string(model.mesh.num_faces()) + " faces, " +
               std::to_string(model.materials.size()) + " materials>";
      });

  // ---- Materials ----
  py::class_<MaterialClass>(m, "MaterialClass")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<MaterialClass>(kw); }))
      .def_readwrite("name", &MaterialClass::name)
      .def_readwrite("color", &MaterialClass::color, "sRGB display colour")
      .def_readwrite("density_kg_m3", &MaterialClass::density_kg_m3)
      .def_readwrite("density_min_kg_m3", &MaterialClass::density_min_kg_m3)
      .def_readwrite("density_max_kg_m3", &MaterialClass::density_max_kg_m3)
      .def_readwrite("friction_static", &MaterialClass::friction_static)
      .def_readwrite("friction_dynamic", &MaterialClass::friction_dynamic)
      .def_readwrite("restitution", &MaterialClass::restitution)
      .def_readwrite("structure", &MaterialClass::structure)
      .def_readwrite("wall_thickness_m", &MaterialClass::wall_thickness_m)
      .def_readwrite("max_solid_thickness_m", &MaterialClass::max_solid_thickness_m)
      .def_readwrite("max_wall_thickness_m", &MaterialClass::max_wall_thickness_m)
      .def_readwrite("source", &MaterialClass::source)
      .def("__repr__", [](const MaterialClass& c) { return "<g2p.MaterialClass '" + c.name + "'>"; });
  py::class_<MaterialTable>(m, "MaterialTable", "The material vocabulary (default: the paper's 12 classes).")
      .def(py::init([]() { return MaterialTable::paper_default(); }))
      .def_static("paper_default", []() { return MaterialTable::paper_default(); })
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& origin) {
            return unwrap(MaterialTable::from_json(text, origin));
          },
          py::arg("json_text"), py::arg("origin") = "<json>")
      .def_static("load", [](const std::string& path) { return unwrap(MaterialTable::load(path)); })
      .def_static(
          "from_classes",
          [](std::vector<MaterialClass> classes, std::string name) {
            return unwrap(MaterialTable::from_classes(std::move(classes), std::move(name)));
          },
          py::arg("classes"), py::arg("name") = "custom")
      .def("to_json", &MaterialTable::to_json)
      .def("save", [](const MaterialTable& t, const std::string& path) { throw_if_error(t.save(path)); })
      .def_property_readonly("name", &MaterialTable::name)
      .def_property_readonly("classes", &MaterialTable::classes)
      .def_property_readonly("names",
                             [](const MaterialTable& t) {
                               std::vector<std::string> names;
                               for (const MaterialClass& c : t.classes()) names.push_back(c.name);
                               return names;
                             })
      .def(
          "find", [](const MaterialTable& t, const std::string& name) { return t.find(name); },
          "Label of the class (case-insensitive), or -1 (g2p.UNKNOWN_LABEL).")
      .def("__len__", &MaterialTable::size)
      .def("__getitem__", [](const MaterialTable& t, int label) {
        if (!t.valid_label(label)) throw py::index_error("label " + std::to_string(label));
        return t[label];
      });
  m.attr("UNKNOWN_LABEL") = kUnknownLabel;

  // ---- io ----
  py::class_<ImportOptions>(m, "ImportOptions")
      .def(py::init([](const py::kwargs& kw) { return from_kwargs<ImportOptions>(kw); }))
      .def_readwrite("unit_scale", &ImportOptions::unit_scale, "metres per file unit; 0 = from the format")
      .def_readwrite("height_m", &ImportOptions::height_m, "the object's real height in metres; 0 = the file's")
      .def_readwrite("longest_side_m", &ImportOptions::longest_side_m,
                     "the object's real longest side in metres; 0 = the file's")
      .def_readwrite("up_axis", &ImportOptions::up_axis)
      .def_readwrite("z_up", &ImportOptions::z_up)
      .def_readwrite("load_textures", &ImportOptions::load_textures)
      .def_readwrite("min_extent_m", &ImportOptions::min_extent_m)
      .def_readwrite("max_extent_m", &ImportOptions::max_extent_m)
      .def_readwrite("strict", &ImportOptions::strict)
      .def_readwrite("max_faces", &ImportOptions::max_faces)
      .def_readwrite("isolate_reader", &ImportOptions::isolate_reader,
                     "parse in a child process, so a crash inside assimp is an error (default True)");
  m.def(
      "load_model",
      [](const std::string& path, const py::object& options, const py::kwargs& kwargs) {
        const ImportOptions o = import_options(options, kwargs);
        py::gil_scoped_release release;
        return unwrap(load_model(path, o));
      },
      py::arg("path"), py::arg("options") = py::none(),
      "Reads a model file (glTF/GLB, OBJ, PLY, STL, FBX, ...). Import options as options=g2p.ImportOptions(...) "
      "or as keywords: load_model(path, unit_scale=0.001, up_axis=g2p.UpAxis.Z).");
  m.def(
      "load_model_from_memory",
      [](const py::bytes& data, const std::string& format_hint, const py::object& options, const py::kwargs& kwargs) {
        const ImportOptions o = import_options(options, kwargs);
        const std::string bytes = data;
        py::gil_scoped_release release;
        return unwrap(load_model_from_memory(bytes.data(), bytes.size(), format_hint, o));
      },
      py::arg("data"), py::arg("format_hint"), py::arg("options") = py::none());
  m.def(
      "write_mesh",
      [](const std::string& path, const Mesh& mesh) {
        py::gil_scoped_release release;
        throw_if_error(write_mesh(path, mesh));
      },
      py::arg("path"), py::arg("mesh"), "Writes .obj, .ply or .stl by extension.");
  m.def("is_supported_extension", &is_supported_extension);
}

}  // namespace g2p::python
