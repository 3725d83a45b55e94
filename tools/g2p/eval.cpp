// g2p eval seg: segmentation accuracy over a labelled set of models, as the
// paper's Table 2 (one confusion matrix over the set, IoU per class, mIoU):
// the flags as SegmentationEvalOptions, the library's evaluate, the tables.
// g2p eval mass: mass errors over a CSV of predictions, as the paper's Table 1.
// g2p eval compare: whether one segmenter beats another on the same models (a paired bootstrap of two eval seg
// --json files): the library's compare_segmentation_files, its text and JSON.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.h"
#include "common.h"
#include "g2p/eval.h"
#include "g2p/io.h"
#include "stage_flags.h"

namespace g2p::cli {
namespace {

// What the eval seg flags set: the library's options, with the flags that
// need parsing kept as given.
struct EvalArgs {
  SegmentationEvalOptions options;
  PipelineArgs pipeline;  // --materials, the view, segmenter and refiner flags, --soft, --identifier
  std::string json_out;
};

int run_eval_seg(EvalArgs& args) {
  SegmentationEvalOptions& o = args.options;
  Result<RunOptions> run = run_options(args.pipeline, "", {});
  if (!run.ok()) return fail_or_usage("eval seg", run.status());
  o.materials = std::move(run->materials);
  const PipelineOptions& p = run->pipeline;
  o.views = p.views;
  o.renderer = p.renderer;
  o.segmenter = p.segmenter;
  o.refiner = p.refiner;
  o.identifier = p.identifier;
  o.project.vote.mode = p.project.vote.mode;
  // One line per model as it is scored; what degraded first.
  o.on_model = [](const SegmentationModelEval& m) {
    for (const std::string& w : m.warnings) std::cerr << "g2p eval seg: warning: " << w << "\n";
    std::printf(
        "%-28s 2D: %9.0f px, accuracy %6.2f %%, mIoU %6.2f %% | 3D: %8.4f m^2, accuracy %6.2f %%, mIoU %6.2f %%\n",
        m.key.c_str(), m.pixels.total(), 100.0 * m.pixels.accuracy(), 100.0 * m.pixels.mean_iou(), m.faces.total(),
        100.0 * m.faces.accuracy(), 100.0 * m.faces.mean_iou());
    std::fflush(stdout);
  };

  SegmentationEvaluator evaluator(o);
  if (Status s = evaluator.prepare(); !s.ok()) return fail_or_usage("eval seg", s);
  Result<SegmentationEval> eval = evaluator.run();
  if (!eval.ok()) return fail("eval seg", eval.status());
  std::cout << "\n" << eval->to_text();
  if (!args.json_out.empty()) {
    std::ofstream out(args.json_out, std::ios::binary | std::ios::trunc);
    out << eval->to_json() << "\n";
    if (!out) {
      std::cerr << "g2p eval seg: error: " << args.json_out << ": cannot write\n";
      return kExitFailure;
    }
  }
  return kExitOk;
}

}  // namespace

struct MassArgs {
  std::string csv;
  std::string json_out;
};

int run_eval_mass(const MassArgs& args) {
  Result<MassErrors> e = mass_errors_from_csv(args.csv);
  if (!e.ok()) {
    std::cerr << "g2p eval mass: error: " << e.status().message() << "\n";
    return kExitFailure;
  }
  std::printf("%d objects: ADE %.4g kg, ALDE %.4f, APE %.4f, MnRE %.4f\n", e->objects, e->ade_kg, e->alde, e->ape,
              e->mnre);
  if (!args.json_out.empty()) {
    if (Status s = write_text_file(args.json_out, mass_errors_json(*e) + "\n"); !s.ok()) return fail("eval mass", s);
  }
  return kExitOk;
}

struct CompareArgs {
  std::string a, b;  // g2p eval seg --json files
  SegmentationComparisonOptions options;
  std::string json_out;
};

// g2p eval compare: is B better than A on the same models? The library's compare_segmentation_files, printed.
int run_eval_compare(const CompareArgs& args) {
  Result<SegmentationComparison> c = compare_segmentation_files(args.a, args.b, args.options);
  if (!c.ok()) {
    std::cerr << "g2p eval compare: error: " << c.status().message() << "\n";
    return kExitFailure;
  }
  if (!c->differing_conditions.empty())
    std::cerr << "g2p eval compare: note: the files were scored differently: " << c->differing_conditions << "\n";
  std::cout << c->to_text() << std::flush;
  if (!args.json_out.empty()) {
    if (Status s = write_text_file(args.json_out, c->to_json() + "\n"); !s.ok()) return fail("eval compare", s);
  }
  return kExitOk;
}

void add_eval_command(CLI::App& app, Command& run) {
  CLI::App* eval = app.add_subcommand("eval", "Measure accuracy against ground truth");
  eval->require_subcommand(1);
  auto args = std::make_shared<EvalArgs>();
  SegmentationEvalOptions& o = args->options;
  CLI::App* seg = eval->add_subcommand(
      "seg", "Material segmentation accuracy over a labelled set: per pixel (2D) and per face after voting (3D)");
  seg->add_option("--assets", o.assets, "Folder with labels.json and NAME/NAME.glb")->capture_default_str();
  seg->add_option("--models", o.models, "Only these models (keys of labels.json)")->delimiter(',');
  PipelineArgs& p = args->pipeline;
  p.identify.name = SegmentationEvalOptions{}.identifier.name;
  seg->add_option("--materials", p.materials, "Material table JSON (default: the paper's 12 classes)");
  seg->add_flag("--anonymize-names", o.anonymize_names, "Replace every name by a meaningless one before segmenting");
  seg->add_flag("--base-color-only", o.base_color_only,
                "Reduce every material to its base colour (metallic and roughness at glTF's defaults), as "
                "image-to-3D meshes are");
  seg->add_option("--truth", o.truth, "labels.json (default: ASSETS/labels.json); keys may be model paths");
  seg->add_option("--split", o.split, "Only the models whose labels.json entry has this \"split\"");
  seg->add_option("--json", args->json_out, "Also write the results as JSON to this file");
  add_view_flags(seg, p.views);
  add_segmenter_flags(seg, p.segmenter);
  seg->add_flag("--soft", p.soft, "Soft votes: add the segmenter's class probabilities instead of one vote");
  add_refiner_flags(seg, p.refiner, SegmentationEvalOptions{}.refiner.name);
  seg->add_option("--identifier", p.identify.name,
                  "Identify each object as g2p run does (auto, names, detector, ...); a confident kind's materials "
                  "weigh the classes read from the image (--kind-prior). none: not identified")
      ->capture_default_str();
  seg->add_flag("--object-from-names", o.object_from_names,
                "Give each object's kind as the model's own names say it, before --anonymize-names removes them, "
                "as a user's --object would (the kind known, the names still removed for segmenting)");
  seg->add_option("--kind-confidence", o.kind_confidence, "The least identification confidence acted on")
      ->check(finite_number(0.0, 1.0))
      ->capture_default_str();
  seg->add_option("--kind-prior", o.kind_prior,
                  "Weight of the classes a confident kind does not list (1 = its materials are not used)")
      ->check(finite_number(0.0, 1.0, true))
      ->capture_default_str();
  seg->add_option("--region-features", o.region_features,
                  "Also write every region's features and true class to this CSV (training the region classifier, "
                  "docs/regions.md)");
  seg->callback([args, &run] { run = [args] { return run_eval_seg(*args); }; });

  auto margs = std::make_shared<MassArgs>();
  CLI::App* mass = eval->add_subcommand(
      "mass", "Mass errors (ADE, ALDE, APE, MnRE as in NeRF2Physics) over a CSV object,predicted_kg,true_kg");
  mass->add_option("csv", margs->csv, "CSV with the header object,predicted_kg,true_kg")->required();
  mass->add_option("--json", margs->json_out, "Also write the results as JSON to this file");
  mass->callback([margs, &run] { run = [margs] { return run_eval_mass(*margs); }; });

  auto cargs = std::make_shared<CompareArgs>();
  CLI::App* compare = eval->add_subcommand(
      "compare",
      "Is B better than A? The paired bootstrap interval of the per-face mIoU difference between two eval seg --json "
      "files that scored the same models");
  compare->add_option("a", cargs->a, "The reference: a g2p eval seg --json file")->required();
  compare->add_option("b", cargs->b, "The candidate: a g2p eval seg --json file of the same models")->required();
  const SegmentationComparisonOptions defaults;
  std::ostringstream confidence_help, resamples_help;
  confidence_help << "Interval coverage (default " << defaults.confidence << ")";
  resamples_help << "Bootstrap resamples (default " << defaults.resamples << ")";
  compare->add_option("--confidence", cargs->options.confidence, confidence_help.str())->check(CLI::Range(0.5, 0.999));
  compare->add_option("--resamples", cargs->options.resamples, resamples_help.str())->check(CLI::Range(10, 1000000));
  compare->add_option("--json", cargs->json_out, "Also write the results as JSON to this file");
  compare->callback([cargs, &run] { run = [cargs] { return run_eval_compare(*cargs); }; });
}

}  // namespace g2p::cli
