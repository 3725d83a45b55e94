// g2p segment and g2p eval seg as a user runs them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "g2p/io.h"
#include "g2p/render.h"
#include "g2p/segment.h"
#include "support/gltf_builder.h"
#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

using test::quote;
using test::run_tool;

TEST(ToolSegment, WritesLabelMapsForEachBackend) {
  const std::string dir = test::scratch_dir("ToolSegment.Backends");
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  test::write_file(dir + "/labels.json", R"({"labels": {"0": "Wood", "1": "Metal"}})");
  for (const std::string& backend : {"pbr", "oracle"}) {
    const std::string out = dir + "/" + backend;
    const std::string set = backend == "oracle" ? " --set labels=" + quote(dir + "/labels.json") : "";
    test::ToolRun r = run_tool("segment " + hammer + " -o " + quote(out) + " --views 2 --resolution 48 --segmenter " +
                               backend + set + " --save-intermediates");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    for (const char* f : {"segmented/view_00_labels.png", "segmented/view_01_labels_index.png",
                          "segmented/view_01_probs.npy", "views/view_00_rgb.png", "segmented/legend.png",
                          "segmented/classes.json", "views/cameras.json", "manifest.json"})
      EXPECT_TRUE(std::filesystem::is_regular_file(out + "/" + f)) << backend << ": " << f;
    EXPECT_NE(r.out.find("g2p segment: 2 views -> "), std::string::npos) << r.out;
  }
  // A folder of one stage, written whole: a rerun with fewer views leaves none of the earlier ones,
  // and the stage commands that start from face labels say what the folder holds.
  const std::string out = dir + "/pbr";
  test::ToolRun again = run_tool("segment " + hammer + " -o " + quote(out) + " --views 1 --resolution 48");
  EXPECT_EQ(again.exit_code, 2) << again.err;  // exists: --overwrite replaces it
  again = run_tool("segment " + hammer + " -o " + quote(out) + " --views 1 --resolution 48 --overwrite");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_FALSE(std::filesystem::exists(out + "/segmented/view_01_labels.png"));
  EXPECT_FALSE(std::filesystem::exists(out + "/views/view_01_rgb.png"));
  test::ToolRun refine = run_tool("refine " + quote(out));
  EXPECT_EQ(refine.exit_code, 2);
  EXPECT_NE(refine.err.find("holds the stages up to segment"), std::string::npos) << refine.err;
  // Seen from below (view 1), the oracle labels the handle Wood and the head Metal.
  Result<ImageU8> index = read_image(dir + "/oracle/segmented/view_01_labels_index.png");
  ASSERT_TRUE(index.ok());
  int wood = 0, metal = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      wood += index->at(x, y, 0) == 0;
      metal += index->at(x, y, 0) == 5;
    }
  EXPECT_GT(wood, 10);
  EXPECT_GT(metal, 10);
}

TEST(ToolSegment, BadSegmenterArguments) {
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  // A folder of this test's own that does not exist yet (a fixed /tmp path failed wherever it did).
  const std::string out = test::scratch_dir("ToolSegment.BadSegmenterArguments") + "/out";
  test::ToolRun r = run_tool("segment " + hammer + " -o " + quote(out) + " --segmenter segformer");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("known: pbr, onnx, oracle"), std::string::npos) << r.err;
  EXPECT_EQ(run_tool("segment " + hammer + " -o " + quote(out) + " --set nonsense").exit_code, 2);
  EXPECT_EQ(run_tool("segment " + hammer + " -o " + quote(out) + " --segmenter onnx").exit_code, 2);  // no model card
  EXPECT_FALSE(std::filesystem::exists(out));  // usage errors write nothing
}

// A backend that degrades (`hybrid` without its network) says so in both
// tools, once per run, and goes on as `pbr`.
TEST(ToolSegment, ADegradedBackendSaysSoInSegmentAndEval) {
  const std::string dir = test::scratch_dir("ToolSegment.Degraded");
  const std::string no_card = " --segmenter hybrid --set model_card=" + quote(dir + "/missing/g2p-materials.json");
  // A real TRELLIS mesh (one material, a baked atlas): it wants the network.
  const std::string chair = test::generated_path("trellis_shell_chair.glb");
  G2P_SKIP_WITHOUT(chair);
  const std::string trellis = quote(chair);
  test::ToolRun r =
      run_tool("segment " + trellis + " -o " + quote(dir + "/out") + " --views 1 --resolution 32" + no_card);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("g2p segment: warning: segment: hybrid: the network cannot run"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing/g2p-materials.json"), std::string::npos) << r.err;
  // The hammer's named materials never wanted it: no warning.
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  r = run_tool("segment " + hammer + " -o " + quote(dir + "/hammer") + " --views 1 --resolution 32" + no_card);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;

  // eval seg: Avocado without its names is one textured material (any
  // texture counts with atlas_charts=0), SheenChair's parts are not; the
  // warning comes once.
  r = run_tool("eval seg --assets " + quote(std::filesystem::path(test::labels_json_path()).parent_path().string()) +
               " --models Avocado SheenChair --anonymize-names --views 1 --resolution 32 --set atlas_charts=0" +
               no_card);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string warning = "g2p eval seg: warning: hybrid: the network cannot run";
  const std::size_t first = r.err.find(warning);
  ASSERT_NE(first, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(warning, first + 1), std::string::npos) << "said once: " << r.err;
}

// The eval tool's mIoU equals one computed here from independently counted pixels.
TEST(ToolEval, ReproducesAHandComputedMeanIoU) {
  const std::string assets = test::scratch_dir("ToolEval.Assets");
  // Two boxes of two materials; truth: Wood and Metal; "prediction": Wood for both.
  test::GltfBuilder g;
  std::vector<Eigen::Vector3f> p;
  std::vector<std::array<unsigned, 3>> t;
  test::box_geometry({0, 0, 0}, {1, 1, 1}, p, t);
  g.add_node(g.add_mesh("a", p, t, g.add_material("a", {0.5f, 0.5f, 0.5f, 1}, 0, 0.5f)));
  p.clear(), t.clear();
  test::box_geometry({1.5f, 0, 0}, {2.5f, 0.6f, 0.8f}, p, t);
  g.add_node(g.add_mesh("b", p, t, g.add_material("b", {0.5f, 0.5f, 0.5f, 1}, 0, 0.5f)));
  std::filesystem::create_directories(assets + "/Boxes");
  g.write(assets + "/Boxes/Boxes.glb");
  test::write_file(assets + "/labels.json", R"({"models": {"Boxes": {"labels": {"0": "Wood", "1": "Metal"}}}})");
  test::write_file(assets + "/predicted.json", R"({"models": {"Boxes": {"labels": {"0": "Wood", "1": "Wood"}}}})");

  test::ToolRun r = run_tool("eval seg --assets " + quote(assets) + " --views 3 --resolution 40 --segmenter oracle " +
                             "--set labels=" + quote(assets + "/predicted.json") + " --set key=Boxes --json " +
                             quote(assets + "/result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| Wood | Metal | mIoU |"), std::string::npos) << r.out;

  // Count each box's pixels in the same views.
  Result<Model> model = load_model(assets + "/Boxes/Boxes.glb");
  ASSERT_TRUE(model.ok());
  ViewOptions vo;
  vo.num_views = 3;
  vo.width = vo.height = 40;
  auto renderer = std::move(*renderer_registry().create("embree"));
  Result<std::vector<View>> views = render_views(*renderer, *model, *make_views(model->mesh, vo));
  ASSERT_TRUE(views.ok());
  double n_a = 0, n_b = 0;
  for (const View& v : *views)
    for (std::size_t i = 0; i < v.face_id.size(); ++i)
      if (v.face_id.data()[i] >= 0) (model->mesh.face_source[v.face_id.data()[i]].material == 0 ? n_a : n_b) += 1;
  ASSERT_GT(n_a, 0);
  ASSERT_GT(n_b, 0);
  // Wood: TP n_a, FP n_b -> n_a / (n_a + n_b). Metal: TP 0 -> 0. mIoU: the mean of the two.
  const nlohmann::json j = nlohmann::json::parse(test::read_file(assets + "/result.json"));
  EXPECT_DOUBLE_EQ(j["total"]["iou"]["Wood"].get<double>(), n_a / (n_a + n_b));
  EXPECT_DOUBLE_EQ(j["total"]["iou"]["Metal"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(j["total"]["miou"].get<double>(), 0.5 * n_a / (n_a + n_b));
  EXPECT_DOUBLE_EQ(j["total"]["total_weight"].get<double>(), n_a + n_b);
  EXPECT_EQ(j["vote"], "hard");
  EXPECT_EQ(j["refiner"], "none");

  // Soft votes of the oracle's one-hot probabilities are its hard votes, and
  // smoothing an all-Wood labelling changes nothing: the same 3D matrix.
  r = run_tool("eval seg --assets " + quote(assets) +
               " --views 3 --resolution 40 --segmenter oracle --set labels=" + quote(assets + "/predicted.json") +
               " --set key=Boxes --soft --refiner smooth --json " + quote(assets + "/refined.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json refined = nlohmann::json::parse(test::read_file(assets + "/refined.json"));
  EXPECT_EQ(refined["total_3d"], j["total_3d"]);

  // Identified as a run identifies it: the file's name, read before the names
  // are removed, makes the object a box; its kind's materials weigh only what
  // the image decides, and the oracle's labels are not the image's: the same
  // scores, with the kind recorded.
  r = run_tool("eval seg --assets " + quote(assets) +
               " --views 3 --resolution 40 --segmenter oracle --set labels=" + quote(assets + "/predicted.json") +
               " --set key=Boxes --anonymize-names --identifier auto --object-from-names --json " +
               quote(assets + "/identified.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json identified = nlohmann::json::parse(test::read_file(assets + "/identified.json"));
  EXPECT_EQ(identified["models"]["Boxes"]["kind"], "box") << identified["models"]["Boxes"].dump();
  EXPECT_EQ(identified["models"]["Boxes"]["kind_prior_applied"], true);
  EXPECT_EQ(identified["total_3d"], j["total_3d"]);
  EXPECT_EQ(run_tool("eval seg --assets " + quote(assets) + " --identifier none --object-from-names").exit_code, 2);
  EXPECT_EQ(run_tool("eval seg --assets " + quote(assets) + " --kind-prior 0").exit_code, 2);
  EXPECT_EQ(run_tool("eval seg --assets " + quote(assets) + " --refiner magic").exit_code, 2);
  EXPECT_EQ(run_tool("eval seg --assets " + quote(assets) + " --refine-set lambda=2").exit_code, 2);
}

// --soft and --refiner reach the 3D score: the shipped network's
// probabilities (names removed, base colour only) are far from one-hot, so
// soft votes label some of SheenChair's faces otherwise than hard ones; the refiner's report goes to the JSON, the
// table stays one line per model.
TEST(ToolEval, SoftVotesAndTheRefinerChangeThe3DScore) {
  const std::string dir = test::scratch_dir("ToolEval.Soft");
  const std::string base = "eval seg --assets " + quote(test::source_path("../shared/assets")) +
                           " --models SheenChair --segmenter learned --anonymize-names --base-color-only --views 3 "
                           "--resolution 64 --json ";
  nlohmann::json runs[3];
  const char* flags[3] = {"", " --soft", " --soft --refiner smooth --refine-set lambda=4"};
  for (int i = 0; i < 3; ++i) {
    const std::string json = dir + "/run" + std::to_string(i) + ".json";
    test::ToolRun r = run_tool(base + quote(json) + flags[i]);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.find("smooth: "), std::string::npos) << "refiner notes belong in the JSON:\n" << r.out;
    runs[i] = nlohmann::json::parse(test::read_file(json));
  }
  EXPECT_EQ(runs[0]["vote"], "hard");
  EXPECT_EQ(runs[1]["vote"], "soft");
  EXPECT_EQ(runs[2]["refiner"], "smooth");
  EXPECT_EQ(runs[2]["refine_settings"], nlohmann::json::array({"lambda=4"}));
  const std::string key = "matrix_rows_truth_columns_predicted_then_unknown";
  EXPECT_NE(runs[1]["total_3d"][key], runs[0]["total_3d"][key]) << "soft votes changed no face";
  EXPECT_NE(runs[2]["total_3d"][key], runs[1]["total_3d"][key]) << "the refiner changed no face";
  const nlohmann::json& report = runs[2]["models"]["SheenChair"]["refine"];
  ASSERT_TRUE(report.is_object()) << runs[2]["models"]["SheenChair"].dump().substr(0, 300);
  EXPECT_GT(report["changed_faces"].get<int>(), 0);
  EXPECT_FALSE(report["notes"].empty());
  EXPECT_FALSE(runs[1]["models"]["SheenChair"].contains("refine"));
}

TEST(ToolEval, SharedAssetsWithAndWithoutNames) {
  const std::string json = test::scratch_dir("ToolEval.Shared") + "/eval.json";
  for (const char* flag : {"", " --anonymize-names"}) {
    test::ToolRun r = run_tool(std::string("eval seg --assets ") + quote(test::source_path("../shared/assets")) +
                               " --views 2 --resolution 48 --models Avocado,SheenChair --json " + quote(json) + flag);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("SheenChair"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("each model weighing the same"), std::string::npos) << r.out;

    // total_3d_per_model is the sum of each model's 3D matrix scaled to one: the tiny avocado
    // (0.006 m^2) counts as much as the chair (1.7 m^2).
    const nlohmann::json j = nlohmann::json::parse(test::read_file(json));
    const nlohmann::json& equal = j["total_3d_per_model"];
    EXPECT_NEAR(equal["total_weight"].get<double>(), 2.0, 1e-9);
    const std::string key = "matrix_rows_truth_columns_predicted_then_unknown";
    for (std::size_t row = 0; row < equal[key].size(); ++row)
      for (std::size_t col = 0; col < equal[key][row].size(); ++col) {
        double expected = 0;
        for (const char* model : {"Avocado", "SheenChair"}) {
          const nlohmann::json& m = j["models"][model]["3d"];
          expected += m[key][row][col].get<double>() / m["total_weight"].get<double>();
        }
        EXPECT_NEAR(equal[key][row][col].get<double>(), expected, 1e-9) << row << " " << col;
      }
    // The bootstrap interval over the two models brackets their per-model mIoU.
    const nlohmann::json& interval = j["total_3d_per_model_interval"];
    ASSERT_TRUE(interval.is_object()) << j.dump();
    EXPECT_LE(interval["low"].get<double>(), equal["miou"].get<double>() + 1e-12);
    EXPECT_GE(interval["high"].get<double>(), equal["miou"].get<double>() - 1e-12);
    EXPECT_EQ(interval["resamples"].get<int>(), 2000);
    EXPECT_NE(r.out.find("% interval over models"), std::string::npos) << r.out;
  }
  EXPECT_EQ(run_tool("eval seg --assets /nonexistent").exit_code, 1);
}

// The shipped network against `pbr` where image-to-3D meshes leave them: no
// names, base colour only. Per face, every shared asset weighing the same
// (docs/training.md has the full-resolution figures).
TEST(ToolEval, ShippedNetworkBeatsPbrWithoutNamesOrPbr) {
  const std::string dir = test::scratch_dir("ToolEval.Shipped");
  double miou[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const std::string json = dir + (k ? "/learned.json" : "/pbr.json");
    test::ToolRun r = run_tool(std::string("eval seg --assets ") + quote(test::source_path("../shared/assets")) +
                               " --anonymize-names --base-color-only --views 6 --resolution 256 --json " + quote(json) +
                               (k ? " --segmenter learned" : " --segmenter pbr"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    miou[k] = nlohmann::json::parse(test::read_file(json))["total_3d_per_model"]["miou"].get<double>();
  }
  // Measured: pbr 4.0 %, learned 14.8 % (6 views at 256 px); 5 points leave room for float noise.
  EXPECT_GT(miou[1], miou[0] + 0.05) << "pbr " << miou[0] << ", learned " << miou[1];
}

// g2p eval compare pairs the models of two eval seg --json files: its mIoU are the files' own (every model weighing
// the same), its interval brackets the difference, and files of other models or no scores are refused.
TEST(ToolEval, CompareTwoScoreFiles) {
  const std::string dir = test::scratch_dir("ToolEval.Compare");
  const std::string base = std::string("eval seg --assets ") + quote(test::source_path("../shared/assets")) +
                           " --anonymize-names --base-color-only --views 3 --resolution 64 --json ";
  for (const char* name : {"pbr", "learned"}) {
    const test::ToolRun r = run_tool(base + quote(dir + "/" + name + ".json") + " --segmenter " + name);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  const nlohmann::json pbr = nlohmann::json::parse(test::read_file(dir + "/pbr.json"));
  const nlohmann::json learned = nlohmann::json::parse(test::read_file(dir + "/learned.json"));
  test::ToolRun r = run_tool("eval compare " + quote(dir + "/pbr.json") + " " + quote(dir + "/learned.json") +
                             " --json " + quote(dir + "/compare.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("B - A: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("paired bootstrap, 2000 resamples of 5 models"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| Wood |"), std::string::npos) << r.out;
  const nlohmann::json c = nlohmann::json::parse(test::read_file(dir + "/compare.json"));
  const double a = pbr["total_3d_per_model"]["miou"].get<double>(),
               b = learned["total_3d_per_model"]["miou"].get<double>();
  EXPECT_NEAR(c["miou_a"].get<double>(), a, 1e-12);
  EXPECT_NEAR(c["miou_b"].get<double>(), b, 1e-12);
  EXPECT_NEAR(c["difference"].get<double>(), b - a, 1e-12);
  EXPECT_LE(c["low"].get<double>(), b - a);
  EXPECT_GE(c["high"].get<double>(), b - a);
  EXPECT_LT(c["low"].get<double>(), c["high"].get<double>());
  EXPECT_EQ(c["models"].get<int>(), 5);
  EXPECT_NEAR(c["iou_per_class"]["Wood"]["b"].get<double>(), learned["total_3d_per_model"]["iou"]["Wood"].get<double>(),
              1e-12);
  // A file against itself: no difference at all.
  r = run_tool("eval compare " + quote(dir + "/pbr.json") + " " + quote(dir + "/pbr.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("B - A: +0.00 points, 95 % interval +0.00 to +0.00"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not resolved"), std::string::npos) << r.out;

  nlohmann::json fewer = pbr;
  fewer["models"].erase("Avocado");
  test::write_file(dir + "/fewer.json", fewer.dump());
  r = run_tool("eval compare " + quote(dir + "/fewer.json") + " " + quote(dir + "/learned.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("score other models (4 and 5 models)"), std::string::npos) << r.err;
  nlohmann::json relabelled = pbr;
  auto& row = relabelled["models"]["Avocado"]["3d"]["matrix_rows_truth_columns_predicted_then_unknown"];
  for (auto& cells : row)
    for (auto& cell : cells) cell = cell.get<double>() * 2;
  test::write_file(dir + "/relabelled.json", relabelled.dump());
  r = run_tool("eval compare " + quote(dir + "/relabelled.json") + " " + quote(dir + "/learned.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("other ground truth on the two sides"), std::string::npos) << r.err;
  test::write_file(dir + "/broken.json", R"({"segmenter": "pbr"})");
  r = run_tool("eval compare " + quote(dir + "/broken.json") + " " + quote(dir + "/learned.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("broken.json: not a g2p eval seg --json file"), std::string::npos) << r.err;
  r = run_tool("eval compare " + quote(dir + "/missing.json") + " " + quote(dir + "/learned.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.json: cannot open"), std::string::npos) << r.err;
}

TEST(ToolProject, WritesFacesPartsAndRefines) {
  const std::string out = test::scratch_dir("ToolProject") + "/out";
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  test::ToolRun r = run_tool("project " + hammer + " -o " + quote(out) +
                             " --views 6 --resolution 64 --refiner smooth --refine-set lambda=0.5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("refine     smooth"), std::string::npos) << r.out;
  for (const char* f : {"faces.csv", "labelled.ply", "parts.json", "refine.json", "projected/view_00_labels.png",
                        "segmented/view_00_labels_index.png", "views/view_00_rgb.png", "manifest.json"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out + "/" + f)) << f;
  const std::string csv = test::read_file(out + "/faces.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 105);  // header + 104 faces
  // The hammer's names say oak handle and steel head: two parts, Wood (92
  // faces) and Metal (12), and every face's label in faces.csv is its material's.
  const nlohmann::json parts = nlohmann::json::parse(test::read_file(out + "/parts.json"));
  ASSERT_EQ(parts["parts"].size(), 2u) << parts.dump();
  std::map<std::string, std::size_t> faces_of;
  for (const auto& p : parts["parts"]) faces_of[p["label"].get<std::string>()] = p["faces"].get<std::size_t>();
  EXPECT_EQ(faces_of["Wood"], 92u);
  EXPECT_EQ(faces_of["Metal"], 12u);
  std::istringstream rows(csv);
  std::string row;
  std::getline(rows, row);  // header
  int checked = 0;
  while (std::getline(rows, row)) {
    const bool oak = row.find(",oak_handle,") != std::string::npos;
    EXPECT_NE(row.find(oak ? ",oak_handle,Wood," : ",steel_head,Metal,"), std::string::npos) << row;
    ++checked;
  }
  EXPECT_EQ(checked, 104);
  EXPECT_EQ(run_tool("project " + hammer + " -o " + quote(out) + " --overwrite --refiner oracle-vlm").exit_code, 2);
  EXPECT_EQ(
      run_tool("project " + hammer + " -o " + quote(out) + " --overwrite --refiner smooth --refine-set x").exit_code,
      2);
  // An existing folder is replaced only with --overwrite.
  r = run_tool("project " + hammer + " -o " + quote(out) + " --views 2 --resolution 64");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
}

// The label columns of a faces.csv (label onwards).
std::string label_columns(const std::string& csv) {
  std::string out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) {
    std::size_t comma = 0;
    for (int k = 0; k < 4 && comma != std::string::npos; ++k) comma = line.find(',', comma + 1);
    out += line.substr(comma == std::string::npos ? 0 : comma) + "\n";
  }
  return out;
}

TEST(ToolRefine, RefinesAProjectFolderLikeProjectDoes) {
  const std::string dir = test::scratch_dir("ToolRefine");
  const std::string hammer = quote(test::source_path("examples/data/hammer.obj"));
  const std::string flags = " --views 4 --resolution 64 --segmenter pbr --set names=off";
  ASSERT_EQ(run_tool("project " + hammer + " -o " + quote(dir + "/a") + flags).exit_code, 0);
  ASSERT_EQ(run_tool("project " + hammer + " -o " + quote(dir + "/b") + flags + " --refiner smooth").exit_code, 0);
  test::ToolRun r = run_tool("refine " + quote(dir + "/a") + " -o " + quote(dir + "/refined"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("refine     smooth"), std::string::npos) << r.out;
  // Rebuilt from the folder, the refinement equals the one done inside g2p project.
  EXPECT_EQ(label_columns(test::read_file(dir + "/refined/faces.csv")),
            label_columns(test::read_file(dir + "/b/faces.csv")));
  // An unreachable VLM loses nothing: the labels stand and the report says why.
  r = run_tool("refine " + quote(dir + "/a") + " -o " + quote(dir + "/vlm") +
               " --refiner vlm --refine-set model=m --refine-set url=http://127.0.0.1:9/v1 --refine-set retries=0");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(label_columns(test::read_file(dir + "/vlm/faces.csv")),
            label_columns(test::read_file(dir + "/a/faces.csv")));
  EXPECT_NE(r.err.find("labels stand"), std::string::npos) << r.err;
  EXPECT_NE(test::read_file(dir + "/vlm/refine.json").find("\"error\""), std::string::npos);
  // A vlm without a model name is a usage error.
  EXPECT_EQ(run_tool("refine " + quote(dir + "/a") + " -o " + quote(dir + "/x") + " --refiner vlm").exit_code, 2);
  // Not a project folder.
  r = run_tool("refine " + quote(dir));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace g2p
