// g2p::run_batch and its inputs: manifests with row-numbered errors, names,
// isolation of a crashing, a hanging and a memory-hungry asset among good
// ones, resume by content hash, and one batch at a time per output.
#include "g2p/batch.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/test_data.h"
#include "support/tool_run.h"

namespace g2p {
namespace {

namespace fs = std::filesystem;

// Six views of 160 x 160 pixels.
RunOptions quick_run() {
  RunOptions r;
  r.pipeline.views.num_views = 6;
  r.pipeline.views.width = r.pipeline.views.height = 160;
  return r;
}

std::string hammer() { return test::source_path("examples/data/hammer.obj"); }

// A copy of the hammer (with its .mtl) as DIR/NAME.obj.
std::string hammer_copy(const std::string& dir, const std::string& name) {
  test::write_file(dir + "/" + name + ".obj", test::read_file(hammer()));
  test::write_file(dir + "/" + name + ".mtl", test::read_file(test::source_path("examples/data/hammer.mtl")));
  return dir + "/" + name + ".obj";
}

// A stand-in for the g2p tool that misbehaves for some models, as a real
// crash or hang would, and runs the real tool for the others: a model whose
// name has "crash" dies by SIGSEGV, "hang" never ends, "hog" allocates 2 GiB.
std::string misbehaving_tool(const std::string& dir) {
  const std::string path = dir + "/g2p-wrapper.sh";
  test::write_file(path,
                   "#!/bin/sh\n"
                   "case \"$2\" in\n"
                   "  *crash*) kill -SEGV $$ ;;\n"
                   "  *hang*) exec sleep 300 ;;\n"
                   "  *hog*) exec /usr/bin/python3 -c 'x = bytearray(2 << 30)' ;;\n"
                   "esac\n"
                   "exec '" G2P_TEST_TOOL "' \"$@\"\n");
  ::chmod(path.c_str(), 0755);
  return path;
}

BatchOptions quick_options(const std::string& out) {
  BatchOptions o;
  o.tool = G2P_TEST_TOOL;
  o.output_dir = out;
  o.run = quick_run();
  return o;
}

const BatchRow& row_named(const BatchResult& r, const std::string& name) {
  for (const BatchRow& row : r.rows)
    if (row.name == name) return row;
  ADD_FAILURE() << "no row " << name;
  static const BatchRow none;
  return none;
}

std::vector<std::string> hidden_leftovers(const std::string& out) {
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.' && name != ".g2p-batch.lock") left.push_back(name);
  }
  return left;
}

// An asset's own options over the library's defaults.
PipelineOptions own_options(const BatchAsset& a) {
  Result<RunOptions> r = parse_options_file(a.options, a.origin);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? r->pipeline : PipelineOptions{};
}

TEST(BatchManifest, CsvAndJsonLinesGiveAssetsWithTheirOwnOptions) {
  const std::string dir = test::scratch_dir("BatchManifest");
  test::write_file(dir + "/assets.csv",
                   "path,name,unit,up,height\n"
                   "# a comment\n"
                   "models/a.obj,first,cm,z,\n"
                   "\n"
                   "\"/abs/b, with comma.glb\",,,,0.3\n");
  Result<std::vector<BatchAsset>> csv = read_batch_manifest(dir + "/assets.csv");
  ASSERT_TRUE(csv.ok()) << csv.status().to_string();
  ASSERT_EQ(csv->size(), 2u);
  EXPECT_EQ((*csv)[0].path, (fs::path(dir) / "models/a.obj").string());  // relative to the manifest
  EXPECT_EQ((*csv)[0].name, "first");
  EXPECT_EQ((*csv)[0].origin, dir + "/assets.csv:3");
  const PipelineOptions first = own_options((*csv)[0]);
  EXPECT_EQ(first.name, "first");
  EXPECT_DOUBLE_EQ(first.import.unit_scale, 0.01);
  EXPECT_EQ(first.import.up_axis, UpAxis::kZ);
  EXPECT_EQ(first.views.num_views, PipelineOptions{}.views.num_views);  // what the row does not give: unchanged
  EXPECT_EQ((*csv)[1].path, "/abs/b, with comma.glb");
  EXPECT_DOUBLE_EQ(own_options((*csv)[1]).import.height_m, 0.3);

  test::write_file(dir + "/assets.jsonl",
                   "{\"path\": \"x.ply\", \"segmenter\": \"learned\", \"longest_side\": 0.5}\n"
                   "{\"path\": \"y.stl\", \"object\": \"exercise bike\", \"options\": {\"views\": {\"count\": 4}, "
                   "\"object\": \"chair\", \"segmenter\": {\"settings\": {\"share\": 0.5}}}}\n");
  Result<std::vector<BatchAsset>> jsonl = read_batch_manifest(dir + "/assets.jsonl");
  ASSERT_TRUE(jsonl.ok()) << jsonl.status().to_string();
  ASSERT_EQ(jsonl->size(), 2u);
  const PipelineOptions x = own_options((*jsonl)[0]);
  EXPECT_DOUBLE_EQ(x.import.longest_side_m, 0.5);
  EXPECT_EQ(x.segmenter.name, "learned");
  EXPECT_EQ((*jsonl)[1].origin, dir + "/assets.jsonl:2");
  const PipelineOptions y = own_options((*jsonl)[1]);
  EXPECT_EQ(y.object, "exercise bike");  // the column over the row's options
  EXPECT_EQ(y.views.num_views, 4);
  EXPECT_EQ(y.segmenter.settings, (BackendSettings{{"share", "0.5"}}));

  // Over a batch's options: the asset's keys win, the batch's others stay.
  BatchOptions batch;
  batch.run = quick_run();
  batch.run.pipeline.import.height_m = 2.0;
  batch.memory_limit_gib = 1.5;
  Result<RunOptions> merged = batch_asset_options((*jsonl)[0], batch);
  ASSERT_TRUE(merged.ok()) << merged.status().to_string();
  EXPECT_DOUBLE_EQ(merged->pipeline.import.longest_side_m, 0.5);
  EXPECT_DOUBLE_EQ(merged->pipeline.import.height_m, 0.0);  // a size given replaces the other
  EXPECT_EQ(merged->pipeline.views.num_views, 6);
  EXPECT_EQ(merged->pipeline.memory_limit_bytes, std::size_t{3} << 29);
}

TEST(BatchManifest, ABadRowIsAnErrorNamingFileAndLine) {
  const std::string dir = test::scratch_dir("BatchManifestBad");
  struct Case {
    std::string file, text, message;
  };
  for (const Case& c : {
           Case{"a.csv", "path,height\nok.obj,0.2\nb.obj,tall\n", "a.csv:3: height 'tall' is not a positive number"},
           Case{"b.csv", "path,colour\nx.obj,red\n", "b.csv:1: unknown column 'colour'"},
           Case{"c.csv", "path,name\nx.obj,a\ny.obj\n", "c.csv:3: 1 fields, the header has 2"},
           Case{"d.csv", "name\nx\n", "d.csv:1: the header row has no 'path' column"},
           Case{"e.csv", "path,name\n\"x.obj,a\n", "e.csv:2: a quoted field is not closed"},
           Case{"f.jsonl", "{\"path\": \"x.obj\"}\n{\"path\": \"y.obj\"\n", "f.jsonl:2: not a JSON object"},
           Case{"g.jsonl", "{\"path\": \"x.obj\"}\n\n{\"name\": \"y\"}\n", "g.jsonl:3: no path"},
           Case{"h.jsonl", "{\"path\": \"x.obj\", \"up\": [1]}\n", "h.jsonl:1: 'up' must be a string or a number"},
           Case{"i.csv", "path,up\nx.obj,sideways\n", "i.csv:2: up 'sideways': unknown up axis"},
           Case{"j.jsonl", "{\"path\": \"x.obj\", \"options\": {\"views\": {\"count\": \"six\"}}}\n",
                "j.jsonl:1: options: views.count: expected an integer, got \"six\""},
           Case{"k.jsonl", "{\"path\": \"x.obj\", \"options\": {\"view\": {}}}\n",
                "k.jsonl:1: options: view: unknown key"},
       }) {
    test::write_file(dir + "/" + c.file, c.text);
    Result<std::vector<BatchAsset>> r = read_batch_manifest(dir + "/" + c.file);
    ASSERT_FALSE(r.ok()) << c.file;
    EXPECT_NE(r.status().message().find(dir + "/" + c.message), std::string::npos) << r.status().message();
  }
  EXPECT_EQ(read_batch_manifest(dir + "/none.csv").status().code(), StatusCode::kNotFound);
  test::write_file(dir + "/list.txt", "x.obj\n");
  EXPECT_EQ(read_batch_manifest(dir + "/list.txt").status().code(), StatusCode::kUnsupported);
}

TEST(BatchInputs, FoldersPatternsAndUniqueNames) {
  const std::string dir = test::scratch_dir("BatchInputs");
  fs::create_directories(dir + "/a/deeper");
  hammer_copy(dir + "/a", "tool");
  hammer_copy(dir + "/a/deeper", "tool");
  test::write_file(dir + "/a/notes.txt", "not a model");
  Result<std::vector<BatchAsset>> folder = list_batch_inputs({dir + "/a"});
  ASSERT_TRUE(folder.ok()) << folder.status().to_string();
  ASSERT_EQ(folder->size(), 2u);  // the two OBJ files; not the .mtl or the .txt
  // Folders g2p wrote inside the input (a batch's -o with its index, a run, a
  // run's temporary folder) hold outputs, not models: the scan skips them.
  for (const char* out : {"/a/out", "/a/out/tool", "/a/.run.g2p-77.tmp"}) fs::create_directories(dir + out);
  test::write_file(dir + "/a/out/index.json", "{}");
  test::write_file(dir + "/a/out/tool/run.json", "{}");
  hammer_copy(dir + "/a/out/tool", "tool");
  hammer_copy(dir + "/a/.run.g2p-77.tmp", "tool");
  Result<std::vector<BatchAsset>> again = list_batch_inputs({dir + "/a"});
  ASSERT_TRUE(again.ok()) << again.status().to_string();
  EXPECT_EQ(again->size(), 2u);
  Result<std::vector<BatchAsset>> pattern = list_batch_inputs({dir + "/a/*.obj", dir + "/missing.glb"});
  ASSERT_TRUE(pattern.ok());
  ASSERT_EQ(pattern->size(), 2u);  // a named file that does not exist is kept: its run says why
  EXPECT_FALSE(list_batch_inputs({dir + "/a/*.fbx"}).ok());

  std::vector<BatchAsset> assets = *folder;
  assets.push_back(BatchAsset{"x/tool.obj", "", {}, "x/tool.obj"});
  assets.push_back(BatchAsset{"y/odd name.obj", "", {}, "y/odd name.obj"});
  ASSERT_TRUE(name_batch_assets(assets).ok());
  EXPECT_EQ(assets[0].name, "tool");
  EXPECT_EQ(assets[1].name, "tool-2");
  EXPECT_EQ(assets[2].name, "tool-3");
  EXPECT_EQ(assets[3].name, "odd_name");
  std::vector<BatchAsset> clash{{"a.obj", "same", {}, "m.csv:2"}, {"b.obj", "same", {}, "m.csv:3"}};
  const Status s = name_batch_assets(clash);
  EXPECT_NE(s.message().find("m.csv:3: the name 'same' is already used by m.csv:2"), std::string::npos) << s.message();
}

// A run refused for a bad flag records the flag's message, not CLI11's
// trailing "Run with --help for more information.".
TEST(BatchRun, ARefusedRunRecordsItsReason) {
  const std::string dir = test::scratch_dir("BatchRefused");
  const std::string model = hammer_copy(dir, "tool");
  // A flag out of range is the batch's own command line: exit 2 before any work.
  test::ToolRun r =
      test::run_tool("batch " + test::quote(model) + " -o " + test::quote(dir + "/flag") + " --views 0 -q");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--views: Value 0 not in range"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/flag"));
  // A run that refuses its options is a row with the run's message.
  r = test::run_tool("batch " + test::quote(model) + " -o " + test::quote(dir + "/out") +
                     " --object 'flying saucer' -q");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string index = test::read_file(dir + "/out/index.csv");
  EXPECT_NE(index.find("tool,failed,\"--object 'flying saucer' names no kind"), std::string::npos) << index;
  EXPECT_EQ(index.find("Run with --help"), std::string::npos) << index;
}

// AddressSanitizer makes the tool several times slower.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kUnderAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kUnderAsan = true;
#else
constexpr bool kUnderAsan = false;
#endif
#else
constexpr bool kUnderAsan = false;
#endif

TEST(BatchRun, ACrashAndAHangAmongGoodAssetsAreRecordedAndTheBatchGoesOn) {
  const std::string dir = test::scratch_dir("BatchIsolation");
  std::vector<BatchAsset> assets;
  for (const char* name : {"good1", "crash", "hang", "good2"})
    assets.push_back(BatchAsset{hammer_copy(dir, name), "", {}, name});
  ASSERT_TRUE(name_batch_assets(assets).ok());
  BatchOptions o = quick_options(dir + "/out");
  o.tool = misbehaving_tool(dir);
  o.jobs = 2;
  // Well above a good model's seconds on a loaded machine. Under
  // AddressSanitizer, with other tests beside it, a good model once took over
  // 15 s (a clean-clone CI run of 2026-11-26).
  const int timeout_s = kUnderAsan ? 60 : 15;
  o.timeout_s = timeout_s;
  o.kill_grace_s = 1;
  std::vector<BatchProgress> progress;
  o.on_progress = [&](const BatchProgress& p) { progress.push_back(p); };
  Result<BatchResult> r = run_batch(assets, o);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->succeeded, 2u);
  EXPECT_EQ(r->failed, 2u);
  EXPECT_EQ(row_named(*r, "crash").status, "failed");
  EXPECT_EQ(row_named(*r, "crash").error, "crashed (SIGSEGV)");
  EXPECT_EQ(row_named(*r, "crash").exit_code, 128 + 11);
  const std::string timed_out = "timed out after " + std::to_string(timeout_s) + " s";
  EXPECT_EQ(row_named(*r, "hang").error, timed_out);
  EXPECT_LT(row_named(*r, "hang").seconds, timeout_s + 10.0);  // stopped, not waited for (300 s)
  for (const char* good : {"good1", "good2"}) {
    const BatchRow& row = row_named(*r, good);
    EXPECT_EQ(row.status, "ok") << row.error;
    EXPECT_EQ(row.parts, 2u);
    EXPECT_EQ(row.materials, (std::vector<std::string>{"Wood", "Metal"}));
    EXPECT_NEAR(row.mass_kg, 1.418, 0.05);
    EXPECT_LT(row.mass_min_kg, row.mass_kg);
    EXPECT_GT(row.mass_max_kg, row.mass_kg);
    EXPECT_GT(row.stage_seconds.at("render"), 0.0);
    EXPECT_GT(row.peak_rss_bytes, 20u << 20);
    EXPECT_TRUE(fs::exists(dir + "/out/" + std::string(good) + "/hammer.xml") ||
                fs::exists(dir + "/out/" + std::string(good) + "/" + good + ".xml"));
  }
  EXPECT_FALSE(fs::exists(dir + "/out/crash"));
  EXPECT_TRUE(hidden_leftovers(dir + "/out").empty());
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back().done, 4u);
  EXPECT_EQ(progress.back().failed, 2u);

  // The index on disk says the same, in list order, as JSON and CSV.
  Result<std::vector<BatchRow>> index = read_batch_index(dir + "/out");
  ASSERT_TRUE(index.ok()) << index.status().to_string();
  ASSERT_EQ(index->size(), 4u);
  EXPECT_EQ((*index)[1].name, "crash");
  EXPECT_EQ((*index)[1].error, "crashed (SIGSEGV)");
  const std::string csv = test::read_file(dir + "/out/index.csv");
  EXPECT_EQ(csv.rfind("name,status,error,", 0), 0u) << csv;
  EXPECT_NE(csv.find("hang,failed," + timed_out + ","), std::string::npos) << csv;
  EXPECT_NE(csv.find("good1,ok,,0,"), std::string::npos) << csv;
}

TEST(BatchRun, TheMemoryLimitReachesEveryWorker) {
  const std::string dir = test::scratch_dir("BatchMemory");
  std::vector<BatchAsset> assets{
      {hammer_copy(dir, "hog"), "", {}, "hog"},
      {hammer_copy(dir, "small"), "", {}, "small"},
      {hammer_copy(dir, "large"), "", R"({"views": {"count": 11, "width": 2048, "height": 2048}})", "large"}};
  ASSERT_TRUE(name_batch_assets(assets).ok());
  BatchOptions o = quick_options(dir + "/out");
  o.tool = misbehaving_tool(dir);
  o.memory_limit_gib = 0.5;
  Result<BatchResult> r = run_batch(assets, o);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(row_named(*r, "small").status, "ok") << row_named(*r, "small").error;
  // A process that allocates past the limit is refused the memory...
  EXPECT_EQ(row_named(*r, "hog").status, "failed");
  EXPECT_NE(row_named(*r, "hog").error.find("MemoryError"), std::string::npos) << row_named(*r, "hog").error;
  // ...and g2p run refuses a run its estimate says will not fit, with its own message.
  EXPECT_EQ(row_named(*r, "large").status, "failed");
  EXPECT_NE(row_named(*r, "large").error.find("out of memory"), std::string::npos) << row_named(*r, "large").error;
}

TEST(BatchRun, ARerunSkipsUnchangedAssetsAndRetriesFailuresOnRequest) {
  const std::string dir = test::scratch_dir("BatchResume");
  test::write_file(dir + "/empty.obj", "");
  std::vector<BatchAsset> assets{{hammer_copy(dir, "a"), "", {}, "a"},
                                 {hammer_copy(dir, "b"), "", {}, "b"},
                                 {dir + "/empty.obj", "", {}, "empty"}};
  ASSERT_TRUE(name_batch_assets(assets).ok());
  const BatchOptions o = quick_options(dir + "/out");
  Result<BatchResult> first = run_batch(assets, o);
  ASSERT_TRUE(first.ok()) << first.status().to_string();
  EXPECT_EQ(first->succeeded, 2u);
  EXPECT_EQ(row_named(*first, "empty").error, "parse error: " + dir + "/empty.obj: the file is empty");
  const std::string key_a = row_named(*first, "a").key;
  const auto written_a = fs::last_write_time(dir + "/out/a/run.json");

  // Unchanged: nothing runs, the rows are the index's.
  Result<BatchResult> again = run_batch(assets, o);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->skipped, 3u);
  EXPECT_EQ(again->succeeded + again->failed, 0u);
  EXPECT_EQ(row_named(*again, "a").status, "ok");
  EXPECT_EQ(row_named(*again, "a").key, key_a);
  EXPECT_EQ(fs::last_write_time(dir + "/out/a/run.json"), written_a);

  // A changed model (or companion .mtl), a changed flag or a lost output runs again.
  test::write_file(dir + "/a.mtl", test::read_file(dir + "/a.mtl") + "# edited\n");
  fs::remove_all(dir + "/out/b");
  Result<BatchResult> changed = run_batch(assets, o);
  ASSERT_TRUE(changed.ok());
  EXPECT_EQ(changed->succeeded, 2u);
  EXPECT_EQ(changed->skipped, 1u);  // the failure stands
  EXPECT_NE(row_named(*changed, "a").key, key_a);
  BatchOptions other = o;
  other.run.pipeline.formats = {"urdf"};
  Result<BatchResult> reflagged = run_batch(assets, other);
  ASSERT_TRUE(reflagged.ok());
  EXPECT_EQ(reflagged->succeeded, 2u);
  EXPECT_TRUE(fs::exists(dir + "/out/a/a.urdf"));
  EXPECT_FALSE(fs::exists(dir + "/out/a/a.xml"));

  // --retry-failed: the recorded failure runs again (and fails again); the rest is kept.
  BatchOptions retry = other;
  retry.retry_failed = true;
  Result<BatchResult> retried = run_batch(assets, retry);
  ASSERT_TRUE(retried.ok());
  EXPECT_EQ(retried->failed, 1u);
  EXPECT_EQ(retried->skipped, 2u);

  // A batch of other assets into the same output keeps the earlier rows.
  std::vector<BatchAsset> more{{hammer_copy(dir, "c"), "", {}, "c"}};
  ASSERT_TRUE(name_batch_assets(more).ok());
  ASSERT_TRUE(run_batch(more, other).ok());
  Result<std::vector<BatchRow>> index = read_batch_index(dir + "/out");
  ASSERT_TRUE(index.ok());
  EXPECT_EQ(index->size(), 4u);
  EXPECT_EQ(index->front().name, "c");  // this batch's rows first
}

TEST(BatchRun, ASecondBatchOnTheSameOutputIsRefused) {
  const std::string dir = test::scratch_dir("BatchLock");
  std::vector<BatchAsset> assets{{hammer_copy(dir, "hang"), "", {}, "hang"}};
  ASSERT_TRUE(name_batch_assets(assets).ok());
  BatchOptions o = quick_options(dir + "/out");
  o.tool = misbehaving_tool(dir);
  o.timeout_s = 30;
  bool second_ran = false;
  Status second;
  // The first batch's progress callback runs while it holds the lock.
  o.on_progress = [&](const BatchProgress& p) {
    if (second_ran || p.running == 0) return;
    second_ran = true;
    BatchOptions again = quick_options(dir + "/out");
    Result<BatchResult> r = run_batch(assets, again);
    second = r.ok() ? Status::Ok() : r.status();
  };
  int polls = 0;
  o.stop_requested = [&] { return second_ran && ++polls > 2 ? SIGINT : 0; };
  Result<BatchResult> first = run_batch(assets, o);
  ASSERT_TRUE(first.ok()) << first.status().to_string();
  ASSERT_TRUE(second_ran);
  EXPECT_EQ(second.code(), StatusCode::kUnavailable);
  EXPECT_NE(second.message().find("another g2p batch (pid " + std::to_string(::getpid()) + ") is writing"),
            std::string::npos)
      << second.message();
  EXPECT_EQ(first->stop_signal, SIGINT);
  EXPECT_EQ(first->cancelled, 1u);
  // Once the first is done, the output is free again.
  std::vector<BatchAsset> good{{hammer(), "", {}, "hammer"}};
  ASSERT_TRUE(name_batch_assets(good).ok());
  Result<BatchResult> later = run_batch(good, quick_options(dir + "/out"));
  ASSERT_TRUE(later.ok()) << later.status().to_string();
  EXPECT_EQ(later->succeeded, 1u);
}

TEST(BatchRun, UnusableOptionsFailBeforeAnyWork) {
  const std::string dir = test::scratch_dir("BatchOptions");
  std::vector<BatchAsset> assets{{hammer(), "hammer", {}, "hammer"}};
  BatchOptions o = quick_options(dir + "/out");
  o.tool = dir + "/no-such-g2p";
  EXPECT_EQ(run_batch(assets, o).status().code(), StatusCode::kNotFound);
  o = quick_options(dir + "/out");
  o.jobs = 0;
  EXPECT_EQ(run_batch(assets, o).status().code(), StatusCode::kInvalidArgument);
  test::write_file(dir + "/file", "x");
  o = quick_options(dir + "/file");
  EXPECT_FALSE(run_batch(assets, o).ok());
  fs::create_directories(dir + "/junk");
  test::write_file(dir + "/junk/index.json", "{\"not\": \"an index\"}");
  o = quick_options(dir + "/junk");
  const Status s = run_batch(assets, o).status();
  EXPECT_NE(s.message().find("index.json: not a g2p batch index"), std::string::npos) << s.message();
  EXPECT_FALSE(fs::exists(dir + "/junk/hammer"));
  // An asset's own options that do not fit: refused naming the asset and the key, nothing runs.
  std::vector<BatchAsset> bad{{hammer(), "hammer", R"({"views": {"layout": "cube"}})", "assets.jsonl:4"}};
  const Status refused = run_batch(bad, quick_options(dir + "/refused")).status();
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.message().find("assets.jsonl:4: options: views.layout: unknown view layout 'cube'"),
            std::string::npos)
      << refused.message();
  EXPECT_FALSE(fs::exists(dir + "/refused/hammer"));
  // Credentials in a URL: never written to the options file its run would read, so refused.
  BatchOptions secret = quick_options(dir + "/secret");
  secret.run.pipeline.estimator = {"vlm", {{"url", "http://me:pw-4711@127.0.0.1:9/v1"}, {"model", "m"}}};
  const Status said = run_batch(assets, secret).status();
  EXPECT_EQ(said.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(said.message().find("estimator.settings.url has credentials in its URL"), std::string::npos)
      << said.message();
  EXPECT_EQ(said.message().find("pw-4711"), std::string::npos);
}

}  // namespace
}  // namespace g2p
