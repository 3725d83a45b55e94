// The `hybrid` segmenter, the default (docs/segment.md, "hybrid"; chosen by the
// rule of docs/accuracy.md): `pbr` where a model's materials are its parts,
// the network libg2p ships where one material covers several parts (issue
// #31), as image-to-3D meshes arrive: one material with a baked base-colour
// atlas (or vertex colours), no names, and metallic at glTF's default or one
// scalar for the whole object.
//
// The rule, per face:
//  1. its names name a class (read as `pbr` and `learned` read them): `pbr`;
//  2. no face of the model is named (scope=model, the default; with
//     scope=material, this face's names only) and its material covers
//     several parts: it covers at least `share` of the model's surface area
//     (faces without a material count as one material) and, with colour=on,
//     an image can show its regions (a baked atlas of at least
//     `atlas_charts` UV charts, or no colour at all). The network decides;
//     when that material's PBR values were authored, `pbr`'s probabilities
//     for the pixel, raised to `prior`, weigh the network's (a prior, never
//     the decision on its own);
//  3. its material's PBR values were authored, or some face of the model is
//     named: `pbr` (per-part materials);
//  4. otherwise (nothing named or authored anywhere): the network with
//     unnamed=network; with unnamed=nameless only when every name the model
//     carries (materials, meshes, nodes, texture files) is a placeholder
//     ("Material.001", "Cube", "material_0"), as an exporter or a generator
//     leaves them, while a curated asset's own unrated words ("potty",
//     "black") keep it per material (the default); `pbr` with unnamed=pbr.
// A model whose every face falls under 1 or 3 is labelled by `pbr` alone and
// the network is neither loaded nor run.
//
// When the network cannot run (no card found, a card or network file that
// cannot be read or loaded), the backend labels everything as `pbr` does and
// says why in warnings() (the pipeline reports it in PipelineResult::warnings).
//
// Settings: model_card = FILE, flip = on|off (as `learned`); the rest in
// HybridOptions. The defaults are the sixth candidate of docs/accuracy.md
// (unnamed=pbr is the fifth; share=0.5 colour=off unnamed=network the first).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>

#include "core/settings.h"
#include "g2p/project.h"
#include "segment/backends.h"
#include "segment/material_lexicon.h"

namespace g2p {
namespace {

struct HybridOptions {
  // Share of the model's surface area (0 to 1) at or above which an unnamed
  // material is taken to cover more than one physical part. 0.99: one
  // material for the whole object, as every image-to-3D output of the
  // generator set has (slivers aside); per-part assets spread their area over
  // several materials.
  double share = 0.99;
  // Exponent (0 to 1) on `pbr`'s probabilities of a several-part material
  // whose PBR was authored, multiplied into the network's: 0 = the network
  // alone, 1 = both count the same.
  double prior = 0.5;
  // Name-evidence threshold (0 to 1] for a face's names to name a class, as
  // `learned`'s names setting; 2 = names never decide.
  double names = 0.9;
  // Where names count (scope=model|material): `model` reads a model of which
  // any face is named with `pbr` throughout (a curated asset: its unnamed
  // materials are parts too), and leaves rule 2 to models nothing names, as
  // generated meshes come; `material` applies rule 2 per material, named
  // model or not (the first candidate, docs/accuracy.md).
  bool model_scope = true;
  // colour=on|off: whether rule 2 also needs the image to be able to show the
  // material's regions: its base colour varies over the surface (a base-colour
  // texture) or there is no colour to read at all (no material, or the
  // importer's default: white, untextured, PBR not authored). A flat-coloured
  // material is one part as far as any image can tell, and `pbr` reads it.
  bool colour = true;
  // With colour=on, the fewest UV charts (connected pieces of the material's
  // surface whose shared edges carry the same UVs on both sides) for its
  // texture to count as a baked atlas that shows regions. A hand-made layout
  // has a few charts (a towel 2, a skirt 9); an atlas baked by an image-to-3D
  // pipeline hundreds. 0 = any texture counts.
  int atlas_charts = 16;
  // unnamed=network|nameless|pbr: rule 4, whether a model that nothing names
  // or authors goes to the network as a whole (`network`), only when its
  // every name is a placeholder (`nameless`), or is read per material by
  // `pbr`.
  enum class Unnamed { kPbr, kNameless, kNetwork };
  Unnamed unnamed = Unnamed::kNameless;
};

class HybridSegmenter final : public Segmenter {
 public:
  SettingsSpec settings() override {
    HybridOptions& o = options_;
    return SettingsSpec("hybrid")
        .text("model_card", card_, "the network's card (g2p-materials.json); \"\" finds the shipped one")
        .flag("flip", flip_, "the network also reads each view mirrored")
        .number("share", o.share, Range::above_to(0, 1), "",
                "share of the surface at or above which an unnamed material is taken to cover several parts")
        .number("prior", o.prior, Range::closed(0, 1), "",
                "exponent on pbr's probabilities of an authored several-part material, joined with the network's")
        .number("names", o.names, Range::above_to(0, 1), "",
                "name-evidence threshold for a face's names to name a class")
        .or_word("off", 2.0)
        .choice("scope", o.model_scope, {{"model", true}, {"material", false}},
                "where names count: a named model is read by pbr throughout (model), or per material")
        .flag("colour", o.colour, "a several-part material also needs colour the image can show regions by")
        .integer("atlas_charts", o.atlas_charts, 0, 1000000, "",
                 "the fewest UV charts for a texture to count as a baked atlas (0: any texture)")
        .choice("unnamed", o.unnamed,
                {{"network", HybridOptions::Unnamed::kNetwork},
                 {"nameless", HybridOptions::Unnamed::kNameless},
                 {"pbr", HybridOptions::Unnamed::kPbr}},
                "a model nothing names goes to the network whole (network), when its names are placeholders "
                "(nameless), or is read by pbr");
  }

  // The settings, then the network they ask for. A network that cannot run is
  // not an error: the backend labels as `pbr` and says so in warnings().
  Status configure(const BackendSettings& settings) override {
    G2P_RETURN_IF_ERROR(Segmenter::configure(settings));
    warnings_.clear();
    unavailable_.clear();
    network_.reset();
    BackendSettings network{{"model_card", card_}, {"flip", flip_ ? "on" : "off"}};
    if (card_.empty()) {
      const std::string card = detail::shipped_model_card();
      if (card.empty()) {
        unavailable_ =
            "hybrid: the shipped network's card g2p-materials.json was not found ($G2P_MODEL_DIR, share/g2p/models "
            "beside libg2p, "
            "the source tree, the install prefix); every material is labelled as 'pbr' labels it";
        return Status::Ok();
      }
      network["model_card"] = card;
    }
    std::unique_ptr<Segmenter> net = detail::make_deferred_onnx_segmenter();
    if (const Status s = net->configure(network); !s.ok()) {  // a card or network file missing or unreadable
      unavailable_ =
          "hybrid: the network cannot run (" + s.message() + "); every material is labelled as 'pbr' labels it";
      return Status::Ok();
    }
    network_ = std::move(net);
    return Status::Ok();
  }

  Status set_model(const Model& model, const MaterialTable& table) override {
    model_ = nullptr;
    G2P_RETURN_IF_ERROR(pbr_->set_model(model, table));
    decide_faces(model, table);
    // The network's absence is news only for a model that wanted it: a
    // curated asset is labelled by `pbr` either way.
    warnings_.clear();
    const bool wanted = std::any_of(by_network_.begin(), by_network_.end(), [](char n) { return n != 0; });
    use_network_ = wanted && network_ != nullptr;
    if (use_network_) {
      if (const Status s = network_->set_model(model, table); !s.ok()) {
        unavailable_ =
            "hybrid: the network cannot run (" + s.message() + "); every material is labelled as 'pbr' labels it";
        network_.reset();
        use_network_ = false;
      }
    }
    if (wanted && !use_network_ && !unavailable_.empty()) warnings_.push_back(unavailable_);
    model_ = &model;
    return Status::Ok();
  }

  Status segment_into(const View& view, LabelMap& out) const override {
    if (model_ == nullptr) return Status::InvalidArgument("hybrid: set_model first");
    if (!use_network_) return pbr_->segment_into(view, out);
    G2P_RETURN_IF_ERROR(network_->segment_into(view, out));
    const bool any_pbr = std::any_of(by_network_.begin(), by_network_.end(), [](char n) { return n != 1; });
    if (!any_pbr) return Status::Ok();
    LabelMap by_pbr;
    G2P_RETURN_IF_ERROR(pbr_->segment_into(view, by_pbr));
    const bool probabilities = !out.probabilities.empty() && !by_pbr.probabilities.empty() &&
                               out.probabilities.channels() == by_pbr.probabilities.channels();
    const int k = probabilities ? out.probabilities.channels() : 0;
    for (int y = 0; y < view.face_id.height(); ++y)
      for (int x = 0; x < view.face_id.width(); ++x) {
        const int f = view.face_id.at(x, y);
        if (f < 0) continue;
        const char how = f < static_cast<int>(by_network_.size()) ? by_network_[static_cast<std::size_t>(f)] : 0;
        if (how == 1) continue;  // the network alone
        if (how == 0 || !probabilities) {
          out.labels.at(x, y) = by_pbr.labels.at(x, y);
          if (probabilities) std::copy_n(by_pbr.probabilities.pixel(x, y), k, out.probabilities.pixel(x, y));
          continue;
        }
        // how == 2: the network weighed by `pbr`'s probabilities raised to `prior`.
        float* p = out.probabilities.pixel(x, y);
        const float* q = by_pbr.probabilities.pixel(x, y);
        double total = 0;
        for (int c = 0; c < k; ++c) {
          p[c] *= static_cast<float>(std::pow(std::max(q[c], 1e-6f), options_.prior));
          total += p[c];
        }
        if (total <= 0) continue;
        int best = 0;
        for (int c = 0; c < k; ++c) {
          p[c] = static_cast<float>(p[c] / total);
          if (p[c] > p[best]) best = c;
        }
        out.labels.at(x, y) = best;
      }
    return Status::Ok();
  }

  std::vector<std::string> warnings() const override { return warnings_; }

  // The network's faces, when it runs: alone, or with `pbr`'s probabilities
  // as a prior (authored PBR on a material that covers several parts, where
  // the issue asks the image to decide and the values to be at most a prior).
  std::vector<std::uint8_t> image_decided_faces() const override {
    if (model_ == nullptr) return {};
    std::vector<std::uint8_t> image(by_network_.size(), 0);
    if (use_network_)
      for (std::size_t f = 0; f < image.size(); ++f) image[f] = by_network_[f] != 0 ? 1 : 0;
    return image;
  }

 private:
  // by_network_ per face: 0 = `pbr`, 1 = the network, 2 = the network with
  // `pbr` as a prior.
  void decide_faces(const Model& model, const MaterialTable& table) {
    const Mesh& mesh = model.mesh;
    const std::vector<char> named = detail::faces_named(model, table, options_.names);
    by_network_.assign(named.size(), 0);
    if (named.empty()) {  // no provenance: one material over everything
      by_network_.assign(static_cast<std::size_t>(mesh.num_faces()), 1);
      return;
    }
    // Area per material; slot 0 holds the faces without one.
    const std::size_t n = model.materials.size();
    std::vector<double> area(n + 1, 0.0);
    double total = 0;
    const auto slot = [&](int m) { return m >= 0 && m < static_cast<int>(n) ? static_cast<std::size_t>(m) + 1 : 0; };
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const double a = face_area(mesh, f);
      area[slot(mesh.face_source[static_cast<std::size_t>(f)].material)] += a;
      total += a;
    }
    // Per slot: can an image show the material's regions (colour=on)?
    const bool any_named = std::any_of(named.begin(), named.end(), [](char c) { return c != 0; });
    if (options_.model_scope && any_named) return;  // 3 throughout: a curated asset, `pbr`
    std::vector<char> shows_regions(n + 1, 1);
    for (std::size_t m = 0; m < n; ++m)
      shows_regions[m + 1] = shows_regions_in_images(model.materials[m], mesh.has_uvs());
    const std::vector<char> coloured = vertex_colours_vary_per_slot(mesh, n);
    if (options_.colour && options_.atlas_charts > 0 && mesh.has_uvs()) {
      std::vector<char> textured_and_large(n + 1, 0);
      for (std::size_t m = 0; m < n; ++m)
        textured_and_large[m + 1] =
            !model.materials[m].base_color_texture.empty() && total > 0 && area[m + 1] >= options_.share * total;
      if (std::any_of(textured_and_large.begin(), textured_and_large.end(), [](char c) { return c != 0; })) {
        const std::vector<int> charts = uv_charts_per_slot(mesh, n);
        for (std::size_t k = 1; k <= n; ++k)
          if (textured_and_large[k] && charts[k] < options_.atlas_charts) shows_regions[k] = 0;
      }
    }
    for (std::size_t k = 0; k <= n; ++k) shows_regions[k] = shows_regions[k] || coloured[k];
    const bool rule4 = options_.unnamed == HybridOptions::Unnamed::kNetwork ||
                       (options_.unnamed == HybridOptions::Unnamed::kNameless && nameless(model));
    for (std::size_t f = 0; f < named.size(); ++f) {
      if (named[f]) continue;  // 1: names decide
      const int m = mesh.face_source[f].material;
      const bool authored = slot(m) > 0 && detail::pbr_authored(model.materials[static_cast<std::size_t>(m)]);
      if (options_.model_scope && any_named) continue;  // 3: a curated asset: `pbr`
      const bool several_parts =
          total > 0 && area[slot(m)] >= options_.share * total && (!options_.colour || shows_regions[slot(m)] != 0);
      if (several_parts)
        by_network_[f] = authored && options_.prior > 0 ? 2 : 1;  // 2: several parts
      else if (rule4 && !authored && !any_named)
        by_network_[f] = 1;  // 4: nothing speaks anywhere
      // else 3: a per-part material: `pbr`
    }
  }

  // Every name the model carries is a placeholder: its materials', meshes',
  // nodes' and texture files' (the names `pbr` reads).
  static bool nameless(const Model& model) {
    for (const SourceMaterial& m : model.materials) {
      if (!detail::is_placeholder_name(m.name)) return false;
      for (const Texture* t : {&m.base_color_texture, &m.metallic_roughness_texture})
        if (!t->uri.empty() && t->uri[0] != '*' &&
            !detail::is_placeholder_name(std::filesystem::path(t->uri).stem().string(),
                                         detail::PlaceholderKind::kTextureFile))
          return false;
    }
    for (const SourcePrimitive& p : model.primitives)
      if (!detail::is_placeholder_name(p.mesh_name) || !detail::is_placeholder_name(p.node_name)) return false;
    return true;
  }

  // colour=on: a base-colour texture shows regions; so does no colour at all
  // (the importer's default material), where `pbr` has nothing to read either.
  // Without UVs a texture renders as one texel: flat.
  static bool shows_regions_in_images(const SourceMaterial& mat, bool has_uvs) {
    if (!mat.base_color_texture.empty()) return has_uvs;
    const bool white = (mat.base_color.head<3>() - Eigen::Vector3f::Ones()).cwiseAbs().maxCoeff() < 1e-3f;
    return white && !detail::pbr_authored(mat);
  }

  // Per material slot: do the vertex colours of its faces differ (by more
  // than 2 % in a channel)? Vertex colours are the other way a generator
  // bakes its appearance (TripoSR).
  static std::vector<char> vertex_colours_vary_per_slot(const Mesh& mesh, std::size_t num_materials) {
    std::vector<char> varies(num_materials + 1, 0);
    if (!mesh.has_colors() || mesh.colors.size() != mesh.positions.size()) return varies;  // none, or stale
    std::vector<Eigen::Vector4f> first(num_materials + 1);
    std::vector<char> seen(num_materials + 1, 0);
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const int m =
          f < static_cast<int>(mesh.face_source.size()) ? mesh.face_source[static_cast<std::size_t>(f)].material : -1;
      const std::size_t k = m >= 0 && static_cast<std::size_t>(m) < num_materials ? static_cast<std::size_t>(m) + 1 : 0;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector4f& c =
            mesh.colors[static_cast<std::size_t>(mesh.triangles[static_cast<std::size_t>(f)][i])];
        if (!seen[k])
          first[k] = c, seen[k] = 1;
        else if ((c - first[k]).cwiseAbs().maxCoeff() > 0.02f)
          varies[k] = 1;
      }
    }
    return varies;
  }

  // UV charts per material slot (slot 0: faces without a material): faces of
  // one material joined across every edge they share (welded positions) whose
  // two ends carry the same UVs in both faces.
  static std::vector<int> uv_charts_per_slot(const Mesh& mesh, std::size_t num_materials) {
    std::vector<int> charts(num_materials + 1, 0);
    Result<FaceGraph> graph = build_face_graph(mesh);
    if (!graph.ok()) return charts;
    const auto slot = [&](int f) {
      const int m = mesh.face_source[static_cast<std::size_t>(f)].material;
      return m >= 0 && static_cast<std::size_t>(m) < num_materials ? static_cast<std::size_t>(m) + 1 : 0;
    };
    std::vector<int> parent(static_cast<std::size_t>(mesh.num_faces()));
    std::iota(parent.begin(), parent.end(), 0);
    const auto root = [&parent](int f) {
      while (parent[static_cast<std::size_t>(f)] != f)
        f = parent[static_cast<std::size_t>(f)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(f)])];
      return f;
    };
    const std::vector<int>& welded = graph->welded_vertex;
    for (int f = 0; f < mesh.num_faces(); ++f)
      for (int k = graph->offsets[static_cast<std::size_t>(f)]; k < graph->offsets[static_cast<std::size_t>(f) + 1];
           ++k) {
        const int g = graph->neighbors[static_cast<std::size_t>(k)];
        if (g <= f || slot(g) != slot(f)) continue;
        int same = 0;  // corners of f with a corner of g at the same place and the same UV
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int a = mesh.triangles[static_cast<std::size_t>(f)][i];
            const int b = mesh.triangles[static_cast<std::size_t>(g)][j];
            same += welded[static_cast<std::size_t>(a)] == welded[static_cast<std::size_t>(b)] &&
                    (mesh.uvs[static_cast<std::size_t>(a)] - mesh.uvs[static_cast<std::size_t>(b)]).norm() < 1e-5f;
          }
        if (same >= 2) parent[static_cast<std::size_t>(root(f))] = root(g);
      }
    for (int f = 0; f < mesh.num_faces(); ++f)
      if (root(f) == f) ++charts[slot(f)];
    return charts;
  }

  HybridOptions options_;
  std::string card_;                    // model_card ("" = the shipped card)
  bool flip_ = false;                   // flip
  std::unique_ptr<Segmenter> network_;  // null when it cannot run
  std::unique_ptr<Segmenter> pbr_ = make_pbr_segmenter();
  std::string unavailable_;            // why the network cannot run (empty: it can, or has not been asked)
  std::vector<std::string> warnings_;  // of the last set_model: unavailable_, when that model wanted the network
  const Model* model_ = nullptr;
  std::vector<char> by_network_;
  bool use_network_ = false;
};

}  // namespace

std::unique_ptr<Segmenter> make_hybrid_segmenter() { return std::make_unique<HybridSegmenter>(); }

}  // namespace g2p
