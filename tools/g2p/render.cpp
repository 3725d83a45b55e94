// g2p render MODEL -o DIR: the render stage on its own.
#include <chrono>
#include <iostream>
#include <memory>

#include "commands.h"
#include "common.h"
#include "g2p/render.h"

namespace g2p::cli {
namespace {

struct RenderArgs {
  std::string path;
  std::string out;
  ImportArgs import;
  ViewArgs views;
  bool buffers = false;
  bool benchmark = false;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Times the face-ID pass and the full pass over all cameras (--benchmark).
int run_benchmark(Renderer& renderer, const std::vector<Camera>& cameras) {
  RenderOptions id_only;
  id_only.shade = id_only.material_buffers = id_only.geometry_buffers = false;
  const RenderOptions full;
  double pixels = 0;
  for (const Camera& c : cameras) pixels += static_cast<double>(c.width) * c.height;
  for (const auto& [name, options] : {std::pair<const char*, RenderOptions>{"face-id pass", id_only},
                                      std::pair<const char*, RenderOptions>{"full pass", full}}) {
    double best = 1e300;
    View view;  // reused: steady-state rendering allocates nothing
    for (int repeat = 0; repeat < 3; ++repeat) {
      const auto start = std::chrono::steady_clock::now();
      for (const Camera& c : cameras) {
        if (Status s = renderer.render_into(c, options, view); !s.ok()) return fail("render", s);
      }
      best = std::min(best, seconds_since(start));
    }
    std::cout << name << ": " << best * 1e3 << " ms for " << cameras.size() << " views, " << pixels / best / 1e6
              << " Mrays/s (primary rays, best of 3)\n";
  }
  return kExitOk;
}

int run_render(const RenderArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("render", args.path, args.import, exit_code);
  if (!model.ok()) return exit_code;

  Result<ViewOptions> options = view_options(args.views);
  if (!options.ok()) {
    std::cerr << "g2p render: " << options.status().message() << "\n";
    return kExitUsage;
  }
  Result<std::vector<Camera>> cameras = make_views(model->mesh, *options);
  if (!cameras.ok()) {
    std::cerr << "g2p render: " << cameras.status().message() << "\n";
    return kExitUsage;
  }
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create(args.views.renderer);
  if (!renderer.ok()) {
    std::cerr << "g2p render: " << renderer.status().message() << "\n";
    return kExitUsage;
  }
  const auto start = std::chrono::steady_clock::now();
  if (Status s = (*renderer)->set_model(*model); !s.ok()) return fail("render", s);
  const double build_s = seconds_since(start);
  if (args.benchmark) {
    std::cout << model->mesh.num_faces() << " triangles, scene build " << build_s * 1e3 << " ms\n";
    return run_benchmark(**renderer, *cameras);
  }
  std::vector<View> views;
  for (const Camera& c : *cameras) {
    Result<View> v = (*renderer)->render(c);
    if (!v.ok()) return fail("render", v.status());
    views.push_back(std::move(*v));
  }
  ViewFileOptions file_options;
  file_options.buffers = args.buffers;
  if (Status s = write_views(args.out, views, file_options); !s.ok()) return fail("render", s);
  std::cout << "rendered " << views.size() << " views of " << model->mesh.num_faces() << " triangles at "
            << args.views.resolution << "x" << args.views.resolution << " in " << seconds_since(start) << " s -> "
            << args.out << "\n";
  return kExitOk;
}

}  // namespace

void add_render_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a model from several views: RGB, face IDs, cameras, buffers");
  cmd->add_option("model", args->path, "Model file")->required();
  cmd->add_option("-o,--output", args->out, "Output folder (created if needed)");
  add_view_flags(cmd, args->views);
  cmd->add_flag("--buffers", args->buffers,
                "Also write depth (.npy), normal, base colour, metallic-roughness and transmission images");
  cmd->add_flag("--benchmark", args->benchmark, "Time the face-ID and full passes instead of writing files");
  add_import_flags(cmd, args->import);
  cmd->callback([args, cmd, &run] {
    if (args->out.empty() && !args->benchmark) throw CLI::RequiredError("--output");
    run = [args] { return run_render(*args); };
  });
}

}  // namespace g2p::cli
