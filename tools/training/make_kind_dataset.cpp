// g2p_make_kind_dataset: training data for the kind classifier (docs/kind-classifier.md).
//
// Every model of the given sweethome3d furniture libraries (unpacked .sh3f
// folders) is labelled with a kind of the object table from its catalogue
// name (kind_from_text, the matcher `--object` uses), or from the reviewed
// labels file where the catalogue's words mislead it, and rendered as the
// `classifier` identifier sees objects (classifier_views: eight eye-level
// views, each cropped to the object on grey). Copy 0 of a model is rendered
// as it is; the other copies look like image-to-3D outputs: colour textures
// flattened to their mean (a coarse bake), sampled per vertex (vertex
// colours) or the whole model grey, light and shadow baked into the colours,
// lumpy surfaces, jittered lights, a random turn and elevation.
//
//   g2p_make_kind_dataset OUT LIBRARY... [--val data/mass-ranges/val.json]
//       [--hold-out KatorLegaz] [--labels tools/training/kind_labels.json] [--copies 3]
//       [--labels-only | --cues-only]
//
// OUT/images/NNNNNN.png (size x size RGB), OUT/views.csv (image, model, split,
// copy, view), OUT/models.csv (model, library, split, name, category, kind,
// rule), OUT/cues.csv (model, copy, then shape_cues() of that copy's mesh by
// shape_cue_names()). --cues-only writes models.csv and cues.csv, the same
// copies without their renders. Models of --val are the validation split; --hold-out libraries are
// not read at all.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "augment.h"
#include "core/csv.h"
#include "g2p/g2p.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Args {
  std::string out;
  std::vector<std::string> libraries;
  std::string val, labels, hold_out = "KatorLegaz";
  int copies = 3, size = 224;
  bool labels_only = false, cues_only = false;
  unsigned seed = 1;
};

struct CatalogueEntry {
  std::string name, category;
};

// A Java properties value (ISO 8859-1 with \uXXXX escapes, BMP only, as the
// catalogues use them) as UTF-8; other escapes become the character.
std::string unescape(const std::string& v) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const auto byte = static_cast<unsigned char>(v[i]);
    if (byte >= 0x80) {  // ISO 8859-1, as Java writes properties files
      out += static_cast<char>(0xC0 | (byte >> 6));
      out += static_cast<char>(0x80 | (byte & 0x3F));
      continue;
    }
    if (v[i] != '\\' || i + 1 >= v.size()) {
      out += v[i];
      continue;
    }
    const char c = v[++i];
    if (c == 'u' && i + 4 < v.size()) {
      const unsigned code = static_cast<unsigned>(std::stoul(v.substr(i + 1, 4), nullptr, 16));
      i += 4;
      if (code < 0x80) {
        out += static_cast<char>(code);
      } else if (code < 0x800) {
        out += static_cast<char>(0xC0 | (code >> 6));
        out += static_cast<char>(0x80 | (code & 0x3F));
      } else {
        out += static_cast<char>(0xE0 | (code >> 12));
        out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (code & 0x3F));
      }
    } else {
      out += c == 'n' ? ' ' : c;
    }
  }
  return out;
}

// The catalogue of an unpacked library (PluginFurnitureCatalog.properties):
// model path inside the library folder (no leading '/') -> name, category.
std::map<std::string, CatalogueEntry> read_catalogue(const std::string& library_dir) {
  std::map<std::string, std::string> name, category, model;
  std::ifstream in(library_dir + "/PluginFurnitureCatalog.properties");
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t eq = line.find('='), hash = line.find('#');
    if (line.empty() || line[0] == '#' || eq == std::string::npos || hash == std::string::npos || hash > eq) continue;
    const std::string key = line.substr(0, hash), id = line.substr(hash + 1, eq - hash - 1);
    const std::string value = unescape(line.substr(eq + 1));
    if (key == "name") name[id] = value;
    if (key == "category") category[id] = value;
    if (key == "model") model[id] = value;
  }
  std::map<std::string, CatalogueEntry> out;
  for (const auto& [id, path] : model) {
    std::string p = path;
    while (!p.empty() && p[0] == '/') p.erase(0, 1);
    out[p] = {name[id], category[id]};
  }
  return out;
}

std::string csv(std::string v) {
  for (char& c : v)
    if (c == '\n' || c == '\r') c = ' ';
  return g2p::detail::csv_field(v);
}

int run(const Args& a) {
  std::set<std::string> val;
  if (!a.val.empty()) {
    std::ifstream in(a.val);
    const json doc = json::parse(in, nullptr, false);
    if (!in || doc.is_discarded() || !doc.contains("models")) {
      std::cerr << "g2p_make_kind_dataset: --val " << a.val << ": not a JSON file with \"models\"\n";
      return 2;
    }
    for (const auto& [key, m] : doc["models"].items()) val.insert(key);
  }
  json labels = json::object();  // catalogue name or model key -> kind ("" = none)
  if (!a.labels.empty()) {
    std::ifstream in(a.labels);
    labels = json::parse(in, nullptr, false);
    if (!in || labels.is_discarded() || !labels.contains("labels")) {
      std::cerr << "g2p_make_kind_dataset: --labels " << a.labels << ": not a JSON file with \"labels\"\n";
      return 2;
    }
    labels = labels["labels"];
  }
  if (fs::exists(a.out)) {
    std::cerr << "g2p_make_kind_dataset: " << a.out << " exists; choose a new folder\n";
    return 2;
  }
  fs::create_directories(a.cues_only ? a.out : a.out + "/images");
  std::ofstream models_csv(a.out + "/models.csv"), cues_csv(a.out + "/cues.csv");
  std::ofstream views_csv;
  if (!a.cues_only) views_csv.open(a.out + "/views.csv");
  views_csv << "image,model,split,copy,view\n";
  cues_csv << "model,copy";
  for (const std::string& name : g2p::shape_cue_names()) cues_csv << "," << name;
  cues_csv << "\n";
  models_csv << "model,library,split,name,category,kind,rule\n";
  const g2p::ObjectTable& table = g2p::ObjectTable::shipped();
  int images = 0, models = 0, skipped = 0;
  for (const std::string& library_dir : a.libraries) {
    const std::string library = fs::path(library_dir).filename().string();
    if (library == a.hold_out) {
      std::cerr << library << ": held out, not read\n";
      continue;
    }
    const std::map<std::string, CatalogueEntry> catalogue = read_catalogue(library_dir);
    if (catalogue.empty()) {
      std::cerr << "g2p_make_kind_dataset: " << library_dir << ": no PluginFurnitureCatalog.properties models\n";
      return 1;
    }
    std::size_t done = 0;
    for (const auto& [path, entry] : catalogue) {
      const std::string key = library + "/" + path;
      std::string kind, rule;
      if (labels.contains(key)) {
        kind = labels[key].get<std::string>(), rule = "hand (model)";
      } else if (labels.contains(entry.name)) {
        kind = labels[entry.name].get<std::string>(), rule = "hand (name)";
      } else {
        g2p::Result<std::string> k = g2p::kind_from_text(table, entry.name);
        kind = k.ok() ? *k : "", rule = k.ok() ? "name" : "no kind";
      }
      const std::string split = val.count(key) ? "val" : "train";
      models_csv << csv(key) << "," << csv(library) << "," << split << "," << csv(entry.name) << ","
                 << csv(entry.category) << "," << csv(kind) << "," << rule << "\n";
      // Validation models are rendered whatever their kind (their kind is
      // scored only where they have one); training models need one.
      if (a.labels_only || (kind.empty() && split == "train")) continue;
      g2p::Result<g2p::Model> loaded = g2p::load_model(library_dir + "/" + path);
      if (!loaded.ok()) {
        std::cerr << "skip " << key << ": " << loaded.status().message() << "\n";
        ++skipped;
        continue;
      }
      ++models;
      const int copies = split == "val" ? 1 : a.copies;
      for (int copy = 0; copy < copies; ++copy) {
        g2p::Model model = *loaded;
        std::mt19937_64 rng(g2p::training::splitmix64(a.seed + static_cast<unsigned>(copy)) ^
                            g2p::training::fnv1a(key));
        std::uniform_real_distribution<double> u(0.0, 1.0);
        g2p::ClassifierViewOptions o;
        o.size = a.size;
        if (copy > 0) {
          // Looks of a generator's output: a coarse bake (the mean colour of
          // each texture), or no colour at all, on lumpy surfaces.
          const double look = u(rng);
          // Half the coarse bakes keep their texture's colour per vertex
          // instead of its mean (a generator that writes vertex colours).
          const bool vertex_colours = look < 0.6 && u(rng) < 0.5;
          if (vertex_colours) g2p::training::texture_to_vertex_colours(model, model.mesh);
          for (g2p::SourceMaterial& m : model.materials) {
            if (vertex_colours) {
              m.base_color_texture = g2p::Texture{};
              m.metallic = 0.f, m.roughness = 0.5f + 0.5f * static_cast<float>(u(rng));
              continue;
            }
            if (look < 0.6 && !m.base_color_texture.empty())
              m.base_color.head<3>() =
                  m.base_color.head<3>().cwiseProduct(g2p::training::mean_linear_colour(m.base_color_texture));
            if (look < 0.6 || look >= 0.85) m.base_color_texture = g2p::Texture{};
            if (look >= 0.85) m.base_color = Eigen::Vector4f(0.8f, 0.8f, 0.8f, 1.f);
            m.metallic = 0.f, m.roughness = 0.5f + 0.5f * static_cast<float>(u(rng));
          }
          g2p::training::add_geometry_noise(model.mesh, 0.001 + 0.004 * u(rng), 0.3, rng());
          // Half the copies have light and shadow baked into their colours,
          // from a key light above the object at a random side.
          if (u(rng) < 0.5) {
            const double azimuth = 2 * M_PI * u(rng), elevation = (20 + 50 * u(rng)) * M_PI / 180;
            const Eigen::Vector3f key_light(std::cos(elevation) * std::cos(azimuth),
                                            std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
            if (g2p::Status s = g2p::training::bake_lighting(model, model.mesh, key_light); !s.ok())
              std::cerr << "no baked light on " << key << ": " << s.message() << "\n";
          }
          g2p::training::turn(model.mesh, 2 * M_PI * u(rng));
          o.elevation_deg = 5 + 25 * u(rng);
          o.lights = g2p::training::jittered_studio_lights(rng);
        }
        const std::vector<double> cues = g2p::shape_cues(model.mesh);
        if (!cues.empty()) {
          cues_csv << csv(key) << "," << copy;
          for (double c : cues) cues_csv << "," << c;
          cues_csv << "\n";
        }
        if (a.cues_only) continue;
        g2p::Result<std::unique_ptr<g2p::Renderer>> renderer = g2p::renderer_registry().create("embree");
        if (!renderer.ok() || !(*renderer)->set_model(model).ok()) break;
        g2p::Result<std::vector<g2p::ImageU8>> views = g2p::classifier_views(**renderer, model.mesh, o);
        if (!views.ok()) {
          std::cerr << "skip " << key << ": " << views.status().message() << "\n";
          break;
        }
        for (std::size_t v = 0; v < views->size(); ++v) {
          char name[32];
          std::snprintf(name, sizeof name, "%06d.png", images++);
          if (!g2p::write_image(a.out + "/images/" + name, (*views)[v]).ok()) {
            std::cerr << "g2p_make_kind_dataset: cannot write " << a.out << "/images/" << name << "\n";
            return 1;
          }
          views_csv << name << "," << csv(key) << "," << split << "," << copy << "," << v << "\n";
        }
      }
      if (++done % 50 == 0) std::cerr << library << ": " << done << "/" << catalogue.size() << " models\n";
    }
  }
  std::cout << (a.cues_only ? "models measured " : "models rendered ") << models << ", skipped " << skipped
            << ", images " << images << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Training data for the kind classifier (docs/kind-classifier.md)"};
  Args a;
  app.add_option("out", a.out, "Output folder (must not exist)")->required();
  app.add_option("libraries", a.libraries, "Unpacked furniture libraries (folder name = library name)")->required();
  app.add_option("--val", a.val, "Models of the validation split (data/mass-ranges/val.json)");
  app.add_option("--hold-out", a.hold_out, "A library not read at all (default KatorLegaz)");
  app.add_option("--labels", a.labels, "Reviewed kinds by catalogue name or model (JSON: {\"labels\": {...}})");
  app.add_option("--copies", a.copies, "Renders per training model; copies after the first look generated (default 3)")
      ->check(CLI::Range(1, 16));
  app.add_option("--size", a.size, "Image side, pixels (default 224, the classifier's)")->check(CLI::Range(32, 1024));
  app.add_option("--seed", a.seed, "Random seed (default 1)");
  app.add_flag("--labels-only", a.labels_only, "Write OUT/models.csv only (to review the labels)");
  app.add_flag("--cues-only", a.cues_only, "Write OUT/models.csv and OUT/cues.csv, without renders");
  CLI11_PARSE(app, argc, argv);
  return run(a);
}
