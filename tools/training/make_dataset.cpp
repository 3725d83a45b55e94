// g2p_make_dataset: training data for a material segmentation network, made
// with libg2p's own importer and renderer (docs/training.md).
//
//   g2p_make_dataset OUT LIBRARY_DIR... [--views 8] [--size 160] [--seed 1]
//                    [--overrides tools/training/overrides.json] [--test KatorLegaz,Reallusion]
//                    [--pbr-defaults 0.5] [--flat-textures 0.25] [--white 0.1]
//                    [--geometry-noise 0.3] [--random-lights 0.3]
//                    [--normals]
//
// Each LIBRARY_DIR is an unpacked furniture library (Sweet Home 3D's .sh3f
// zip files hold OBJ/MTL models); its folder name names the library. Every
// source material gets a class from its name and its texture's file name
// through libg2p's material lexicon (material_name_evidence), unless the
// overrides file says otherwise; materials without a clear class are left
// unlabelled (255, ignored by the loss). Each model is turned about its up
// axis at random and rendered from `views` of 24 directions on a Fibonacci
// sphere, with a random field of view and background; its PBR values are set
// to glTF's defaults, its colour textures flattened to their mean colour or its
// colours whitened on a share of models, mild geometry noise added to a share
// and the studio lights jittered per view on a share, as image-to-3D meshes
// arrive. Writes OUT/images/*.png (RGB),
// OUT/labels/*.png (class index, 255 = unlabelled or background),
// with --normals OUT/normals/*.png (camera-space unit normal n as 8-bit
// 127.5 * (n + 1), background 128: the encoding segment/onnx reads),
// OUT/manifest.csv (one row per image, with its library and split),
// OUT/labels.json (per model and material, the ground truth `g2p eval seg`
// reads), OUT/stats.json (labelled faces and area per class and split) and
// OUT/materials.csv (every material of every model read: its name, texture,
// colour, share of the model's area, the rule that labelled it and the class;
// the list to review when extending the overrides file).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "augment.h"
#include "core/ascii.h"
#include "core/csv.h"
#include "g2p/g2p.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Class of one material: overrides first (per model, then per name), then the
// lexicon: one class at full strength (>= 0.9) and no other above 0.5.
int label_material(const g2p::SourceMaterial& m, const std::string& model_key, const json& overrides,
                   const g2p::MaterialTable& table, std::string& why) {
  auto from_override = [&](const json& entry, const std::string& where) {
    const std::string v = entry.get<std::string>();
    why = where;
    return v == "ignore" ? g2p::kUnknownLabel : table.find(v);
  };
  if (overrides.contains("models") && overrides["models"].contains(model_key) &&
      overrides["models"][model_key].contains(m.name))
    return from_override(overrides["models"][model_key][m.name], "override (model)");
  const std::string name = g2p::detail::lower_case(m.name);
  if (overrides.contains("names") && overrides["names"].contains(name))
    return from_override(overrides["names"][name], "override (name)");
  std::string text = m.name;
  if (!m.base_color_texture.uri.empty()) text += " " + fs::path(m.base_color_texture.uri).stem().string();
  const std::vector<float> e = g2p::material_name_evidence(text, table);
  int best = -1;
  float top = 0.f, second = 0.f;
  for (int c = 0; c < static_cast<int>(e.size()); ++c) {
    if (e[static_cast<std::size_t>(c)] > top) {
      second = top;
      top = e[static_cast<std::size_t>(c)];
      best = c;
    } else {
      second = std::max(second, e[static_cast<std::size_t>(c)]);
    }
  }
  if (best >= 0 && top >= 0.9f && second < 0.5f) {
    why = "lexicon";
    return best;
  }
  why = top > 0 ? "ambiguous" : "no material word";
  return g2p::kUnknownLabel;
}

// Turns the model about +Z by `yaw` radians (positions and normals).
struct Args {
  std::string out;
  std::vector<std::string> libraries;
  int views = 8, size = 160;
  unsigned seed = 1;
  std::string overrides, test = "KatorLegaz,Reallusion";
  double min_labelled = 0.2;
  int max_models = 0;
  double pbr_defaults = 0.5;    // share of models given glTF's default metallic and roughness
  double flat_textures = 0.25;  // share of models whose colour textures become their mean colour
  double white = 0.1;           // share of models whose colours all become a light grey (shape only)
  double geometry_noise = 0.3;  // share of models given mild geometry noise
  double random_lights = 0.3;   // share of models whose views are lit by jittered studio lights
  bool normals = false;         // also write OUT/normals (camera-space normals)
};

// The view's camera-space normals (camera_space_normals) as 8 bits per
// channel: round(127.5 * (n + 1)); background pixels hold 128 (n = 0).
g2p::ImageU8 encode_normals(const g2p::View& view) {
  const g2p::ImageF n = g2p::camera_space_normals(view);
  g2p::ImageU8 out(n.width(), n.height(), 3, 128);
  for (std::size_t i = 0; i < n.size(); ++i)
    out.data()[i] = static_cast<std::uint8_t>(std::lround(std::clamp(127.5f * (n.data()[i] + 1.f), 0.f, 255.f)));
  return out;
}

int run(const Args& a) {
  const g2p::MaterialTable& table = g2p::MaterialTable::paper_default();
  json overrides = json::object();
  if (!a.overrides.empty()) {
    std::ifstream in(a.overrides);
    overrides = json::parse(in, nullptr, false);
    if (!in || overrides.is_discarded()) {
      std::cerr << "g2p_make_dataset: " << a.overrides << ": cannot read it as JSON\n";
      return 1;
    }
  }
  std::set<std::string> test_libraries;
  {
    std::stringstream s(a.test);
    for (std::string t; std::getline(s, t, ',');) test_libraries.insert(t);
  }
  if (fs::exists(a.out)) {
    std::cerr << "g2p_make_dataset: " << a.out << " exists; choose a new folder\n";
    return 2;
  }
  fs::create_directories(a.out + "/images");
  fs::create_directories(a.out + "/labels");
  if (a.normals) fs::create_directories(a.out + "/normals");
  std::ofstream materials_csv(a.out + "/materials.csv");
  // One record per line: line breaks in a name become spaces, commas and
  // quotes are quoted (RFC 4180).
  const auto csv_cell = [](std::string v) {
    for (char& c : v)
      if (c == '\n' || c == '\r') c = ' ';
    return g2p::detail::csv_field(v);
  };
  materials_csv << "library,model,split,material,name,texture,r,g,b,area_share,rule,class\n";
  std::ofstream manifest(a.out + "/manifest.csv");
  manifest << "image,library,model,split,view,labelled_pixels";
  for (const g2p::MaterialClass& c : table.classes()) manifest << "," << c.name;
  manifest << "\n";
  json labels_json = {{"models", json::object()}};
  // stats[split][class] = {faces, area}
  std::map<std::string, std::vector<std::pair<long, double>>> stats;
  std::map<std::string, std::map<std::string, int>> reasons;
  std::mt19937 rng(a.seed);
  int image_count = 0, models_used = 0, models_skipped = 0;

  for (const std::string& library_dir : a.libraries) {
    const std::string library = fs::path(library_dir).filename().string();
    const std::string split = test_libraries.count(library) ? "test" : "train";
    std::vector<fs::path> objs;
    for (const auto& e : fs::recursive_directory_iterator(library_dir))
      if (e.is_regular_file() && g2p::detail::lower_case(e.path().extension().string()) == ".obj")
        objs.push_back(e.path());
    std::sort(objs.begin(), objs.end());
    if (a.max_models > 0 && static_cast<int>(objs.size()) > a.max_models) objs.resize(a.max_models);
    auto& split_stats = stats[split];
    split_stats.resize(static_cast<std::size_t>(table.size()), {0, 0.0});
    for (std::size_t mi = 0; mi < objs.size(); ++mi) {
      const std::string key = library + "/" + fs::relative(objs[mi], library_dir).string();
      g2p::Result<g2p::Model> loaded = g2p::load_model(objs[mi].string());
      if (!loaded.ok()) {
        std::cerr << "skip " << key << ": " << loaded.status().message() << "\n";
        ++models_skipped;
        continue;
      }
      g2p::Model& model = *loaded;
      std::vector<int> material_label(model.materials.size(), g2p::kUnknownLabel);
      std::vector<std::string> material_rule(model.materials.size());
      json model_labels = json::object();
      for (std::size_t m = 0; m < model.materials.size(); ++m) {
        material_label[m] = label_material(model.materials[m], key, overrides, table, material_rule[m]);
        ++reasons[split][material_rule[m]];
        model_labels[std::to_string(m)] =
            table.valid_label(material_label[m]) ? table[material_label[m]].name : std::string("ignore");
      }
      const g2p::Mesh& mesh = model.mesh;
      {
        std::vector<double> material_area(model.materials.size(), 0.0);
        double total = 0;
        for (int f = 0; f < mesh.num_faces(); ++f) {
          const int m = mesh.face_source[static_cast<std::size_t>(f)].material;
          const double fa = g2p::face_area(mesh, f);
          total += fa;
          if (m >= 0 && m < static_cast<int>(material_area.size())) material_area[static_cast<std::size_t>(m)] += fa;
        }
        for (std::size_t m = 0; m < model.materials.size(); ++m) {
          const g2p::SourceMaterial& sm = model.materials[m];
          char colour[64];
          std::snprintf(colour, sizeof colour, "%.3f,%.3f,%.3f", sm.base_color.x(), sm.base_color.y(),
                        sm.base_color.z());
          materials_csv << library << "," << csv_cell(key) << "," << split << "," << m << "," << csv_cell(sm.name)
                        << "," << csv_cell(fs::path(sm.base_color_texture.uri).filename().string()) << "," << colour
                        << "," << (total > 0 ? material_area[m] / total : 0.0) << "," << material_rule[m] << ","
                        << (table.valid_label(material_label[m]) ? table[material_label[m]].name : "") << "\n";
        }
      }
      std::vector<int> face_label(static_cast<std::size_t>(mesh.num_faces()), g2p::kUnknownLabel);
      double labelled_area = 0, area = 0;
      for (int f = 0; f < mesh.num_faces(); ++f) {
        const int m = mesh.face_source[static_cast<std::size_t>(f)].material;
        const int l = m >= 0 && m < static_cast<int>(material_label.size())
                          ? material_label[static_cast<std::size_t>(m)]
                          : g2p::kUnknownLabel;
        face_label[static_cast<std::size_t>(f)] = l;
        const double fa = g2p::face_area(mesh, f);
        area += fa;
        if (l >= 0) labelled_area += fa;
      }
      if (!(area > 0) || labelled_area < a.min_labelled * area) {
        ++models_skipped;
        continue;
      }
      labels_json["models"][key] = {{"labels", model_labels}, {"library", library}, {"split", split}};
      for (int f = 0; f < mesh.num_faces(); ++f) {
        const int l = face_label[static_cast<std::size_t>(f)];
        if (l < 0) continue;
        split_stats[static_cast<std::size_t>(l)].first += 1;
        split_stats[static_cast<std::size_t>(l)].second += g2p::face_area(mesh, f);
      }
      ++models_used;

      // Appearance as generated meshes have it: glTF's default metallic and
      // roughness on a share of models (--pbr-defaults), colour textures
      // flattened to their mean colour on a share (--flat-textures: coarse
      // bakes and untextured models keep the colour but lose the pattern),
      // colours whitened (shape only) on a share (--white).
      std::uniform_real_distribution<double> u(0.0, 1.0);
      const bool defaults = u(rng) < a.pbr_defaults, flat = u(rng) < a.flat_textures, white = u(rng) < a.white;
      for (g2p::SourceMaterial& m : model.materials) {
        if (defaults) m.metallic = 1.f, m.roughness = 1.f, m.metallic_roughness_texture = g2p::Texture{};
        if (flat && !white && !m.base_color_texture.empty())
          m.base_color.head<3>() =
              m.base_color.head<3>().cwiseProduct(g2p::training::mean_linear_colour(m.base_color_texture));
        if (flat || white) m.base_color_texture = g2p::Texture{};
        if (white) m.base_color = Eigen::Vector4f(0.8f, 0.8f, 0.8f, m.base_color.w());
      }
      // Geometry noise draws from a generator of its own (seeded by --seed
      // and the model), so the views and appearance above are those of
      // datasets made without it.
      std::mt19937_64 noise_rng(g2p::training::splitmix64(a.seed) ^ g2p::training::fnv1a(key));
      if (u(noise_rng) < a.geometry_noise)
        g2p::training::add_geometry_noise(model.mesh, 0.001 * (1 + 2 * u(noise_rng)), 0.15, noise_rng());
      // Lights likewise: jittered studio lights per view on a share of models.
      std::mt19937_64 light_rng(g2p::training::splitmix64(a.seed + 1) ^ g2p::training::fnv1a(key));
      const bool relit = u(light_rng) < a.random_lights;
      g2p::training::turn(model.mesh, 2 * M_PI * u(rng));
      g2p::ViewOptions vo;
      vo.layout = g2p::ViewLayout::kFibonacci;
      vo.num_views = 24;
      vo.width = vo.height = a.size;
      vo.fov_y_deg = 30 + 20 * u(rng);
      g2p::Result<std::vector<g2p::Camera>> cameras = g2p::make_views(model.mesh, vo);
      if (!cameras.ok()) continue;
      std::vector<g2p::Camera> chosen = *cameras;
      std::shuffle(chosen.begin(), chosen.end(), rng);
      chosen.resize(std::min<std::size_t>(chosen.size(), static_cast<std::size_t>(a.views)));
      g2p::Result<std::unique_ptr<g2p::Renderer>> renderer = g2p::renderer_registry().create("embree");
      if (!renderer.ok() || !(*renderer)->set_model(model).ok()) continue;
      for (std::size_t v = 0; v < chosen.size(); ++v) {
        g2p::RenderOptions ro;
        ro.material_buffers = false;
        ro.geometry_buffers = a.normals;
        if (relit) ro.lights = g2p::training::jittered_studio_lights(light_rng);
        for (auto& c : ro.background) c = static_cast<std::uint8_t>(255 * u(rng));
        g2p::Result<g2p::View> view = (*renderer)->render(chosen[v], ro);
        if (!view.ok()) continue;
        g2p::ImageU8 label(a.size, a.size, 1, 255);
        std::vector<long> counts(static_cast<std::size_t>(table.size()), 0);
        long labelled = 0;
        for (int y = 0; y < a.size; ++y)
          for (int x = 0; x < a.size; ++x) {
            const int f = view->face_id.at(x, y);
            const int l = f >= 0 ? face_label[static_cast<std::size_t>(f)] : g2p::kUnknownLabel;
            if (l < 0) continue;
            label.at(x, y) = static_cast<std::uint8_t>(l);
            ++counts[static_cast<std::size_t>(l)];
            ++labelled;
          }
        if (labelled < 0.02 * a.size * a.size) continue;
        char name[64];
        std::snprintf(name, sizeof name, "%06d.png", image_count++);
        if (!g2p::write_image(a.out + "/images/" + name, view->rgb).ok() ||
            !g2p::write_image(a.out + "/labels/" + name, label).ok() ||
            (a.normals && !g2p::write_image(a.out + "/normals/" + name, encode_normals(*view)).ok())) {
          std::cerr << "g2p_make_dataset: cannot write " << a.out << "/images/" << name << "\n";
          return 1;
        }
        manifest << name << "," << library << "," << key << "," << split << "," << v << "," << labelled;
        for (long c : counts) manifest << "," << c;
        manifest << "\n";
      }
      if ((mi + 1) % 50 == 0) std::cerr << library << ": " << mi + 1 << "/" << objs.size() << " models\n";
    }
  }
  json s = {{"models_used", models_used}, {"models_skipped", models_skipped}, {"images", image_count}};
  for (const auto& [split, per_class] : stats) {
    json classes = json::object();
    for (int c = 0; c < table.size(); ++c)
      classes[table[c].name] = {{"faces", per_class[static_cast<std::size_t>(c)].first},
                                {"area_m2", per_class[static_cast<std::size_t>(c)].second}};
    s["splits"][split] = {{"classes", classes}, {"materials_by_rule", reasons[split]}};
  }
  std::ofstream(a.out + "/labels.json") << labels_json.dump(1) << "\n";
  std::ofstream(a.out + "/stats.json") << s.dump(2) << "\n";
  std::cout << s.dump(2) << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Training data for a material segmentation network (docs/training.md)"};
  Args a;
  app.add_option("out", a.out, "Output folder (must not exist)")->required();
  app.add_option("libraries", a.libraries, "Unpacked furniture libraries (folder name = library name)")->required();
  app.add_option("--views", a.views, "Images per model (default 8)")->check(CLI::Range(1, 24));
  app.add_option("--size", a.size, "Image width and height, pixels (default 160)")->check(CLI::Range(32, 1024));
  app.add_option("--seed", a.seed, "Random seed (default 1)");
  app.add_option("--overrides", a.overrides, "Reviewed label overrides (JSON)");
  app.add_option("--test", a.test, "Libraries held out as the test split (default KatorLegaz,Reallusion)");
  app.add_option("--min-labelled", a.min_labelled, "Skip models with less labelled area (default 0.2)");
  // The augmentations: each a share of the models, in [0, 1].
  auto share = [&app](const char* flag, double& value, const std::string& what) {
    app.add_option(flag, value, "Share of models " + what)->check(CLI::Range(0.0, 1.0));
  };
  share("--pbr-defaults", a.pbr_defaults, "rendered with glTF's default metallic and roughness (default 0.5)");
  share("--flat-textures", a.flat_textures, "whose colour textures are replaced by their mean colour (default 0.25)");
  share("--white", a.white, "rendered light grey, shape only (default 0.1)");
  share("--geometry-noise", a.geometry_noise,
        "whose vertices move by 0.1-0.3 % of the diagonal, normals tilted (default 0.3)");
  share("--random-lights", a.random_lights, "whose views are lit by jittered studio lights (default 0.3)");
  app.add_flag("--normals", a.normals, "Also write OUT/normals: camera-space normals for networks that take them");
  app.add_option("--max-models", a.max_models, "At most this many models per library (0 = all)");
  CLI11_PARSE(app, argc, argv);
  return run(a);
}
