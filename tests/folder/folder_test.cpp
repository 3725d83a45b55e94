// The output folder's module: its manifest round-trips, a folder read back
// resumes to what the run gave, and folders of another version or with a
// missing model are refused with a message that names them.
#include "g2p/folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/test_data.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

PipelineOptions quick_options() {
  PipelineOptions o;
  o.views.num_views = 4;
  o.views.width = o.views.height = 128;
  return o;
}

std::string hammer() { return test::source_path("examples/data/hammer.obj"); }

TEST(FolderManifest, RoundTripsThroughItsJson) {
  FolderManifest m;
  m.written_by = "g2p test";
  m.stage = Stage::kProperties;
  m.model = "/data/hammer.obj";
  m.import.height_m = 3.0;
  m.import.up_axis = UpAxis::kZ;
  m.import.strict = false;
  m.kind_scale = 1.75;
  m.import_warnings = {"the model looks normalised"};
  m.anonymize_names = true;
  m.identification.candidates.push_back(KindGuess{"hammer", 0.75, "names", "file name 'hammer'"});
  m.kind = "hammer";
  m.size_assumed_m = 0.3;
  m.project.vote.mode = VoteMode::kSoft;
  m.project.partition.min_part_area_fraction = 0.01;
  const std::string dir = test::scratch_dir("FolderManifestRoundTrip");
  test::write_file(dir + "/manifest.json", folder_manifest_json(m));
  Result<FolderManifest> back = read_folder_manifest(dir);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(folder_manifest_json(*back), folder_manifest_json(m));
  EXPECT_EQ(back->stage, Stage::kProperties);
  EXPECT_DOUBLE_EQ(back->import.height_m, 3.0);
  EXPECT_DOUBLE_EQ(back->kind_scale, 1.75);
  EXPECT_EQ(back->project.vote.mode, VoteMode::kSoft);
  EXPECT_EQ(back->identification.kind(), "hammer");
}

TEST(FolderManifest, AnotherVersionIsRefusedNamingBoth) {
  const std::string dir = test::scratch_dir("FolderManifestVersion");
  FolderManifest m;
  m.model = "/data/hammer.obj";
  std::string text = folder_manifest_json(m);
  text.replace(text.find("\"version\": 2"), 12, "\"version\": 3");
  fs::create_directories(dir + "/newer");
  fs::create_directories(dir + "/older");
  test::write_file(dir + "/newer/manifest.json", text);
  Result<FolderManifest> newer = read_folder_manifest(dir + "/newer");
  ASSERT_FALSE(newer.ok());
  EXPECT_NE(newer.status().message().find("folder version 3"), std::string::npos) << newer.status().message();
  EXPECT_NE(newer.status().message().find("version 2"), std::string::npos) << newer.status().message();
  test::write_file(dir + "/older/project.json", R"({"format": "g2p-project", "version": 1})");
  Result<FolderManifest> older = read_folder_manifest(dir + "/older");
  ASSERT_FALSE(older.ok());
  EXPECT_NE(older.status().message().find("version 1"), std::string::npos) << older.status().message();
}

TEST(PipelineResume, AFolderResumedGivesWhatTheRunGave) {
  PipelineOptions o = quick_options();
  o.import.height_m = 2.0;  // a size given at import travels with the folder
  Pipeline pipeline(o);
  Result<PipelineResult> run = pipeline.run_file(hammer());
  ASSERT_TRUE(run.ok()) << run.status().to_string();
  const std::string dir = test::scratch_dir("PipelineResume") + "/out";
  OutputOptions output;
  output.intermediates = true;  // keeps completed/, so export can start after properties
  ASSERT_TRUE(write_pipeline_output(dir, *run, o, output).ok());

  for (Stage first : {Stage::kRefine, Stage::kComplete, Stage::kProperties, Stage::kDecompose}) {
    Result<PipelineResult> resumed = Pipeline(quick_options()).resume(dir, first, Stage::kExport);
    ASSERT_TRUE(resumed.ok()) << to_string(first) << ": " << resumed.status().to_string();
    EXPECT_EQ(resumed->stages.front().stage, first);
    EXPECT_EQ(resumed->last_stage, Stage::kExport);
    EXPECT_EQ(resumed->projection.labels.label, run->projection.labels.label) << to_string(first);
    EXPECT_EQ(resumed->properties.object.mass_kg, run->properties.object.mass_kg) << to_string(first);
    EXPECT_EQ(resumed->asset.parts.size(), run->asset.parts.size());
    EXPECT_NEAR(bounds(resumed->model.mesh).sizes().z(), 2.0, 1e-6);
    EXPECT_EQ(resumed->kind.name, "hammer");
  }
  // A state without what its first stage needs is refused, naming the command that makes it.
  PipelineResult empty;
  Result<PipelineResult> bad = Pipeline(quick_options()).resume(std::move(empty), Stage::kComplete, Stage::kExport);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("g2p project"), std::string::npos) << bad.status().message();
}

TEST(PipelineResume, AFolderWithoutClosedPartsClosesThemAgainAndSaysSo) {
  Pipeline pipeline(quick_options());
  Result<PipelineResult> run = pipeline.run_file(hammer());
  ASSERT_TRUE(run.ok());
  const std::string dir = test::scratch_dir("PipelineResumeNoParts") + "/out";
  ASSERT_TRUE(write_pipeline_output(dir, *run, quick_options()).ok());  // no completed/ without intermediates
  Result<FolderState> state = read_pipeline_folder(dir, Stage::kDecompose);
  ASSERT_TRUE(state.ok()) << state.status().to_string();
  EXPECT_EQ(state->first, Stage::kComplete);
  ASSERT_FALSE(state->notes.empty());
  EXPECT_NE(state->notes.front().find("--save-intermediates"), std::string::npos) << state->notes.front();
  // The model moved away: the folder cannot be read, and the message names the model.
  const std::string copy = test::scratch_dir("PipelineResumeMoved") + "/hammer.obj";
  fs::copy_file(hammer(), copy);
  PipelineOptions o = quick_options();
  Result<PipelineResult> moved_run = Pipeline(o).run_file(copy);
  ASSERT_TRUE(moved_run.ok());
  ASSERT_TRUE(write_pipeline_output(dir + "-moved", *moved_run, o).ok());
  fs::remove(copy);
  Result<FolderState> moved = read_pipeline_folder(dir + "-moved", Stage::kComplete);
  ASSERT_FALSE(moved.ok());
  EXPECT_NE(moved.status().message().find("hammer.obj"), std::string::npos) << moved.status().message();
}

}  // namespace
}  // namespace g2p
