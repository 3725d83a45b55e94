// g2p render MODEL -o DIR: the render stage on its own.
#include <chrono>
#include <iostream>
#include <memory>

#include "commands.h"
#include "common.h"
#include "g2p/pipeline.h"
#include "g2p/render.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

struct RenderArgs {
  std::string path;
  std::string out;
  PipelineArgs pipeline;  // its import and view flags
  bool buffers = false, benchmark = false, overwrite = false;
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

// --benchmark: the renderer timed on the model's cameras; nothing is written.
int run_render_benchmark(const RenderArgs& args) {
  int exit_code = kExitOk;
  Result<Model> model = load_with_flags("render", args.path, args.pipeline.import, exit_code);
  if (!model.ok()) return exit_code;
  Result<ViewOptions> options = view_options(args.pipeline.views);
  Result<std::vector<Camera>> cameras =
      options.ok() ? make_views(model->mesh, *options) : Result<std::vector<Camera>>(options.status());
  if (!cameras.ok()) return fail_or_usage("render", cameras.status());
  Result<std::unique_ptr<Renderer>> renderer = renderer_registry().create(args.pipeline.views.renderer);
  if (!renderer.ok()) return fail_or_usage("render", renderer.status());
  const auto start = std::chrono::steady_clock::now();
  if (Status s = (*renderer)->set_model(*model); !s.ok()) return fail("render", s);
  std::cout << model->mesh.num_faces() << " triangles, scene build " << seconds_since(start) * 1e3 << " ms\n";
  return run_benchmark(**renderer, *cameras);
}

// The pipeline to its render stage, written as a folder's views/ (write_pipeline_output).
int run_render(const RenderArgs& args) {
  if (args.benchmark) return run_render_benchmark(args);
  OutputOptions output;
  output.written_by = "g2p render";
  output.overwrite = args.overwrite;
  output.intermediates = args.buffers;
  output.input_path = args.path;
  if (Status s = check_output_folder(args.out, output); !s.ok()) return fail_or_usage("render", s.with_context("-o"));
  Result<PipelineOptions> options = pipeline_options(args.pipeline);
  if (!options.ok()) return fail_or_usage("render", options.status());
  options->last_stage = Stage::kRender;
  Pipeline pipeline(std::move(*options));
  if (Status s = pipeline.prepare(); !s.ok()) return fail_or_usage("render", s);  // an unknown renderer
  Result<PipelineResult> r = pipeline.run_file(args.path);
  if (!r.ok()) return fail("render", r.status());
  if (Status s = write_pipeline_output(args.out, *r, pipeline.options(), output); !s.ok()) return fail("render", s);
  std::cout << "rendered " << r->views.size() << " views of " << r->model.mesh.num_faces() << " triangles at "
            << args.pipeline.views.resolution << "x" << args.pipeline.views.resolution << " in " << r->seconds
            << " s -> " << args.out << "/views\n";
  return kExitOk;
}

}  // namespace

void add_render_command(CLI::App& app, Command& run) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a model from several views: RGB, face IDs, cameras, buffers");
  cmd->add_option("model", args->path, "Model file")->required();
  cmd->add_option("-o,--output", args->out,
                  "Output folder, as a g2p run folder's views/ and manifest.json (must not exist unless --overwrite)");
  cmd->add_flag("--overwrite", args->overwrite,
                "Replace an existing output folder (only once the new one is complete)");
  add_view_flags(cmd, args->pipeline.views);
  cmd->add_flag("--buffers", args->buffers,
                "Also write depth (.npy), normal, base colour, metallic-roughness and transmission images");
  cmd->add_flag("--benchmark", args->benchmark, "Time the face-ID and full passes instead of writing files");
  add_import_flags(cmd, args->pipeline.import);
  cmd->callback([args, cmd, &run] {
    if (args->out.empty() && !args->benchmark) throw CLI::RequiredError("--output");
    run = [args] { return run_render(*args); };
  });
}

}  // namespace g2p::cli
