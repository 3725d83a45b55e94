#include "common.h"

#include <cmath>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "g2p/options_file.h"
#include "stage_flags.h"

namespace g2p::cli {

int fail(const std::string& command, const Status& status) {
  std::cerr << "g2p " << command << ": error: " << status.to_string() << "\n";
  return kExitFailure;
}

int fail_or_usage(const std::string& command, const Status& status) {
  if (status.code() != StatusCode::kInvalidArgument && status.code() != StatusCode::kNotFound)
    return fail(command, status);
  std::cerr << "g2p " << command << ": " << status.message() << "\n";
  return kExitUsage;
}

CLI::Validator finite_number(double lo, double hi, bool above_lo) {
  std::ostringstream range;
  range << (above_lo ? "(" : "[") << lo << ", " << hi << "]";
  return CLI::Validator(
      [lo, hi, above_lo, range = range.str()](std::string& text) -> std::string {
        double v = 0.0;
        std::size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size() || !std::isfinite(v) || v < lo || v > hi || (above_lo && v == lo))
          return "takes a number in " + range + ", not '" + text + "'";
        return std::string();
      },
      "NUMBER in " + range.str());
}

void add_import_flags(CLI::App* cmd, ImportArgs& args) {
  cmd->add_option("--unit", args.unit,
                  "Unit of the file's coordinates: m, cm, mm, km, in, ft (default: from the format)");
  cmd->add_option("--height", args.height,
                  "The object's real height in metres: the model is scaled to it (for generated meshes, which come "
                  "normalised to about a metre)")
      ->check(finite_number(0.0, 1e5, true));
  cmd->add_option("--longest-side", args.longest_side,
                  "The object's real longest side in metres: the model is scaled to it")
      ->check(finite_number(0.0, 1e5, true));
  cmd->add_option("--up", args.up, "Up axis of the file: auto, x, y, z")
      ->transform(CLI::IsMember({"auto", "x", "y", "z"}, CLI::ignore_case));
  cmd->add_flag("--keep-axes", args.keep_axes, "Keep the file's axes (default: rotate its up axis to +Z)");
  cmd->add_flag("--no-textures", args.no_textures, "Do not decode textures");
  cmd->add_flag("--lenient", args.lenient,
                "Import a damaged file anyway: drop its bad triangles with a warning instead of refusing it");
}

Result<ImportOptions> import_options(const ImportArgs& args) {
  ImportOptions options;
  if (!args.unit.empty()) {
    Result<double> scale = parse_unit(args.unit);
    if (!scale.ok()) return scale.status();
    options.unit_scale = *scale;
  }
  Result<UpAxis> up = parse_up_axis(args.up);
  if (!up.ok()) return up.status().with_context("--up");
  options.up_axis = *up;
  options.z_up = !args.keep_axes;
  options.load_textures = !args.no_textures;
  options.strict = !args.lenient;
  options.height_m = args.height;
  options.longest_side_m = args.longest_side;
  return options;
}

Result<Model> load_with_flags(const std::string& command, const std::string& path, const ImportArgs& args,
                              int& exit_code) {
  Result<ImportOptions> options = import_options(args);
  if (!options.ok()) {
    std::cerr << "g2p " << command << ": " << options.status().message() << "\n";
    exit_code = kExitUsage;
    return options.status();
  }
  Result<Model> model = load_model(path, *options);
  if (!model.ok()) {
    std::cerr << "g2p " << command << ": error: " << model.status().to_string() << "\n";
    exit_code = kExitFailure;
  }
  return model;
}

void add_view_flags(CLI::App* cmd, ViewArgs& args) {
  cmd->add_option("--views", args.views, "Number of views around the object")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--resolution", args.resolution, "Image width and height in pixels")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  cmd->add_option("--layout", args.layout, "View layout: sphere (poles and two rings), fibonacci, turntable")
      ->transform(CLI::IsMember({"sphere", "fibonacci", "turntable"}, CLI::ignore_case))
      ->capture_default_str();
  cmd->add_option("--fov", args.fov, "Vertical field of view in degrees")
      ->check(CLI::Range(5.0, 150.0))
      ->capture_default_str();
  cmd->add_flag("--ortho", args.ortho, "Orthographic projection");
  cmd->add_option("--renderer", args.renderer, "Render backend: " + backend_list(renderer_registry().names()))
      ->capture_default_str();
}

std::string backend_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

Result<ViewOptions> view_options(const ViewArgs& args) {
  ViewOptions o;
  o.num_views = args.views;
  o.width = o.height = args.resolution;
  Result<ViewLayout> layout = parse_view_layout(args.layout);
  if (!layout.ok()) return layout.status().with_context("--layout");
  o.layout = *layout;
  o.fov_y_deg = args.fov;
  o.orthographic = args.ortho;
  return o;
}

Result<std::vector<View>> render_with_flags(const std::string& command, const Model& model, const ViewArgs& args,
                                            int& exit_code) {
  auto fail = [&](const Status& s, int code) -> Result<std::vector<View>> {
    std::cerr << "g2p " << command << ": " << (code == kExitUsage ? s.message() : "error: " + s.to_string()) << "\n";
    exit_code = code;
    return s;
  };
  Result<ViewOptions> options = view_options(args);
  if (!options.ok()) return fail(options.status(), kExitUsage);
  Result<std::vector<Camera>> cameras = make_views(model.mesh, *options);
  if (!cameras.ok()) return fail(cameras.status(), kExitUsage);
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create(args.renderer);
  if (!renderer.ok()) return fail(renderer.status(), kExitUsage);
  Result<std::vector<View>> views = render_views(**renderer, model, *cameras);
  if (!views.ok()) return fail(views.status(), kExitFailure);
  return views;
}

void add_segmenter_flags(CLI::App* cmd, SegmenterArgs& args) {
  cmd->add_option("--segmenter", args.name, "Segmenter: " + backend_list(segmenter_registry().names()))
      ->capture_default_str();
  cmd->add_option("--set", args.settings,
                  "Segmenter setting KEY=VALUE, repeatable (`g2p run --settings segment:NAME` lists them)");
}

void add_identify_flags(CLI::App* cmd, IdentifyArgs& args) {
  cmd->add_option("--object", args.object,
                  "What the object is, in your words (\"exercise bike\", \"a wooden chair with metal legs\"): "
                  "it wins over what the names and the views suggest; words that name no kind of the object "
                  "table are an error naming the nearest (g2p identify --list)");
  cmd->add_option("--identifier", args.name,
                  "How the object is identified: " + backend_list(identifier_registry().names()) +
                      " (auto: --object, else names and the COCO detector)")
      ->capture_default_str();
  cmd->add_option("--identify-set", args.settings,
                  "Identifier setting KEY=VALUE, repeatable (`g2p run --settings identify:NAME` lists them)");
  cmd->add_option("--size-from", args.size_from,
                  "A mesh that looks normalised, with no --height or --longest-side: kind (its kind's typical "
                  "size when identified confidently) or file (keep the file's size)")
      ->check(CLI::IsMember({"kind", "file"}))
      ->capture_default_str();
  cmd->add_option("--kind-confidence", args.kind_confidence,
                  "The least identification confidence for which the run acts on the kind: assumes its size "
                  "(--size-from kind), weighs its structure and hidden mass, checks the mass against its range")
      ->check(finite_number(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--kind-prior", args.kind_prior,
                  "Weight, against 1, of the material classes a confidently identified kind does not list, on the "
                  "classes read from the image (1 = the kind's materials are not used)")
      ->check(finite_number(0.0, 1.0, true))
      ->capture_default_str();
  cmd->add_option("--kind-mass", args.kind_mass,
                  "on: with a kind the run acts on, each class covers no more of the surface than the kind allows "
                  "and each part's structure is chosen against the kind's mass at the object's size "
                  "and, of an unknown kind, against everyday objects' bulk density (docs/properties.md); off: none")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
}

Result<std::unique_ptr<Segmenter>> make_segmenter_flag(const std::string& command, const SegmenterArgs& args,
                                                       int& exit_code) {
  Result<BackendSettings> settings = parse_settings(args.settings);
  Result<std::unique_ptr<Segmenter>> s =
      settings.ok() ? make_segmenter(args.name, *settings) : Result<std::unique_ptr<Segmenter>>(settings.status());
  if (!s.ok()) {
    const bool usage = s.status().code() == StatusCode::kInvalidArgument || s.status().code() == StatusCode::kNotFound;
    std::cerr << "g2p " << command << ": " << (usage ? "" : "error: ") << (settings.ok() ? "" : "--set: ")
              << s.status().message() << "\n";
    exit_code = usage ? kExitUsage : kExitFailure;
  }
  return s;
}

Result<MaterialTable> load_table_flag(const std::string& command, const std::string& path, int& exit_code) {
  if (path.empty()) return MaterialTable::paper_default();
  Result<MaterialTable> t = MaterialTable::load(path);
  if (!t.ok()) {
    std::cerr << "g2p " << command << ": error: " << t.status().to_string() << "\n";
    exit_code = kExitFailure;
  }
  return t;
}

}  // namespace g2p::cli
