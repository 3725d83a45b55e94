// Options files (g2p/options_file.h): every option a file holds comes back as
// written, a partial file lays its keys over a base, and anything refused is
// named by its key path.
#include "g2p/options_file.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_data.h"

namespace g2p {
namespace {

// Options with every field a file holds away from its default.
RunOptions unusual() {
  RunOptions r;
  PipelineOptions& o = r.pipeline;
  o.import.unit_scale = 0.0254;
  o.import.longest_side_m = 1.25;
  o.import.up_axis = UpAxis::kZ;
  o.import.z_up = false;
  o.import.load_textures = false;
  o.import.strict = false;
  o.anonymize_names = o.base_color_only = true;
  o.renderer = {"embree", {}};
  o.views.num_views = 7;
  o.views.width = 320;
  o.views.height = 240;
  o.views.layout = ViewLayout::kTurntable;
  o.views.fov_y_deg = 35.5;
  o.views.orthographic = true;
  o.views.margin = 1.3;
  o.views.elevation_deg = 12.0;
  o.identifier = {"names", {}};
  o.object = "chair";
  o.kind_confidence = 0.45;
  o.size_policy = SizePolicy::kFile;
  o.kind_properties = false;
  o.kind_prior = 0.2;
  o.segmenter = {"pbr", {{"colour", "off"}}};
  o.project.vote.mode = VoteMode::kSoft;
  o.project.vote.weight_by_angle = o.project.vote.weight_by_footprint = true;
  o.project.weld_tolerance = 2e-6;
  o.project.partition.min_part_area_fraction = 0.01;
  o.project.partition.merge_max_confidence = 0.4;
  o.refiner = {"none", {}};
  o.completer = {"partition", {{"resolution", "48"}}};
  o.completion_fallback = "";
  o.keep_closed_parts = false;
  o.estimator = {"table", {}};
  o.decomposer = {"hull", {}};
  o.decompose.max_hulls = 5;
  o.decompose.max_vertices_per_hull = 32;
  o.decompose.min_depth_m = 0.002;
  o.decompose.measure_resolution = 40;
  o.decompose.coverage_tolerance = 0.05;
  o.decompose.max_hulls_per_object = 12;
  o.name = "thing";
  o.formats = {"urdf", "glb"};
  o.export_options.free_joint = false;
  o.export_options.use_static_friction = true;
  o.export_options.scale_contacts = false;
  o.export_options.contact_sink = 0.05;
  o.export_options.timestep_s = 0.001;
  o.memory_limit_bytes = std::size_t{3} << 30;
  std::vector<MaterialClass> classes = MaterialTable::paper_default().classes();
  classes[0].density_kg_m3 = classes[0].density_max_kg_m3;
  Result<MaterialTable> table = MaterialTable::from_classes(classes, "heavier");
  EXPECT_TRUE(table.ok()) << table.status().to_string();
  if (table.ok()) r.materials = *table;
  return r;
}

TEST(OptionsFile, EveryOptionComesBackAsWritten) {
  const RunOptions r = unusual();
  const std::string text = options_file_json(r);
  Result<RunOptions> back = parse_options_file(text, "unusual.json");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(options_file_json(*back), text);  // every field a file holds, the table included
  EXPECT_EQ(back->pipeline.views.layout, ViewLayout::kTurntable);
  EXPECT_EQ(back->pipeline.segmenter.settings, (BackendSettings{{"colour", "off"}}));
  EXPECT_EQ(back->pipeline.memory_limit_bytes, std::size_t{3} << 30);
  EXPECT_EQ(back->materials.name(), "heavier");
  // The paper's table is not written; a file without one keeps the base's.
  EXPECT_FALSE(nlohmann::json::parse(options_file_json(RunOptions{})).contains("materials"));

  const std::string path = test::scratch_dir("OptionsFile") + "/options.json";
  ASSERT_TRUE(write_options_file(path, r).ok());
  Result<RunOptions> read = read_options_file(path);
  ASSERT_TRUE(read.ok()) << read.status().to_string();
  EXPECT_EQ(options_file_json(*read), text);
}

TEST(OptionsFile, APartialFileLaysItsKeysOverTheBase) {
  const RunOptions base = unusual();
  Result<RunOptions> r = parse_options_file(
      R"({"views": {"count": 3}, "import": {"height_m": 0.5, "longest_side_m": 0},
          "segmenter": {"name": "hybrid"}, "completer": {"settings": {"resolution": 64}}})",
      "partial.json", base);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->pipeline.views.num_views, 3);
  EXPECT_EQ(r->pipeline.views.width, 320);  // the base's, not the default
  EXPECT_DOUBLE_EQ(r->pipeline.import.height_m, 0.5);
  EXPECT_DOUBLE_EQ(r->pipeline.import.unit_scale, 0.0254);
  EXPECT_EQ(r->pipeline.segmenter.name, "hybrid");
  EXPECT_TRUE(r->pipeline.segmenter.settings.empty());  // pbr's settings do not follow to another backend
  EXPECT_EQ(r->pipeline.completer.name, "partition");
  EXPECT_EQ(r->pipeline.completer.settings, (BackendSettings{{"resolution", "64"}}));  // replaced whole, as text
  EXPECT_EQ(r->materials.name(), "heavier");
  Result<RunOptions> empty = parse_options_file("{}", "empty.json");
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(options_file_json(*empty), options_file_json(RunOptions{}));
}

TEST(OptionsFile, ASecretInAUrlIsNeverWritten) {
  RunOptions r;
  r.pipeline.refiner = {"vlm", {{"url", "https://me:pw-4711@host:8000/v1?key=qk-4711"}, {"model", "m"}}};
  const std::string text = options_file_json(r);
  EXPECT_EQ(text.find("pw-4711"), std::string::npos) << text;
  EXPECT_EQ(text.find("qk-4711"), std::string::npos) << text;
  EXPECT_NE(text.find("https://***@host:8000/v1?key=***"), std::string::npos) << text;
  EXPECT_EQ(options_file_redactions(r), (std::vector<std::string>{"refiner.settings.url"}));
  r.pipeline.refiner.settings["url"] = "http://localhost:8000/v1";
  EXPECT_TRUE(options_file_redactions(r).empty());
}

TEST(OptionsFile, ARefusedValueIsNamedByItsKeyPath) {
  struct Case {
    const char* text;
    const char* message;
  };
  for (const Case& c : {
           Case{"[1]", "f.json: expected a JSON object"},
           Case{"{\"views\": {\"count\": 2.5}}", "f.json: views.count: expected an integer, got 2.5"},
           Case{"{\"views\": {\"cout\": 2}}", "f.json: views.cout: unknown key (known here: count,"},
           Case{"{\"views\": 6}", "f.json: views: expected an object"},
           Case{"{\"formats\": [\"urdf\", 3]}", "f.json: formats: expected a list of strings"},
           Case{"{\"soft\": true}", "f.json: soft: unknown key"},
           Case{"{\"import\": {\"up\": \"w\"}}", "f.json: import.up: unknown up axis 'w'"},
           Case{"{\"project\": {\"vote\": \"loud\"}}", "f.json: project.vote: unknown vote 'loud'"},
           Case{"{\"size_from\": \"guess\"}", "f.json: size_from:"},
           Case{"{\"import\": {\"height_m\": 1, \"longest_side_m\": 2}}", "f.json: import: give height_m or"},
           Case{"{\"memory_limit_gib\": -1}", "f.json: memory_limit_gib: must be 0"},
           Case{"{\"contact_sink\": 0}", "f.json: contact_sink: must lie in (0, 0.5]"},
           Case{"{\"timestep_s\": -1}", "f.json: timestep_s: must lie in [0, 0.1] s"},
           Case{"{\"segmenter\": {\"settings\": {\"share\": [1]}}}", "f.json: segmenter.settings.share: expected"},
           Case{"{\"version\": 9}", "f.json: options file version 9, and this libg2p reads version 1"},
           Case{"{\"format\": \"g2p-folder\"}", "f.json: format \"g2p-folder\" is not \"g2p-options\""},
           Case{"{\"materials\": {\"classes\": 3}}", "f.json: materials"},
           Case{"not json", "f.json: not JSON"},
       }) {
    Result<RunOptions> r = parse_options_file(c.text, "f.json");
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_NE(r.status().message().find(c.message), std::string::npos) << c.text << " -> " << r.status().message();
  }
  EXPECT_EQ(read_options_file("/no/such/options.json").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace g2p
