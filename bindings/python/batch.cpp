// g2p.batch: many models, each through `g2p run` in its own worker process
// (g2p::run_batch, with the GIL released), the index as rows (dicts) or a
// pandas DataFrame. Ctrl-C stops the batch cleanly and raises KeyboardInterrupt.
// With client= (a dask.distributed Client) the same per-asset work runs on the
// cluster's workers: DaskExecutor submits one task per asset, each running
// g2p::run_batch_asset there; the index and the lock stay here.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <map>

#include <pybind11/eval.h>

#include "bindings.h"

namespace g2p::python {

namespace {

namespace fs = std::filesystem;

py::dict row_dict(const BatchRow& r) {
  py::dict d;
  d["name"] = r.name;
  d["status"] = r.status;
  d["error"] = r.error;
  d["exit_code"] = r.exit_code;
  d["input"] = r.input;
  d["origin"] = r.origin;
  d["key"] = r.key;
  d["parts"] = r.parts;
  d["materials"] = r.materials;
  d["mass_kg"] = r.mass_kg;
  d["mass_min_kg"] = r.mass_min_kg;
  d["mass_max_kg"] = r.mass_max_kg;
  d["kind"] = r.kind;
  d["kind_confidence"] = r.kind_confidence;
  d["mass_in_kind_range"] = r.mass_in_kind_range;
  d["seconds"] = r.seconds;
  d["stage_seconds"] = r.stage_seconds;
  d["peak_rss_mib"] = static_cast<double>(r.peak_rss_bytes) / (1024.0 * 1024.0);
  d["output"] = r.output;
  d["finished_at"] = r.finished_at;
  return d;
}

BatchRow row_of_dict(const py::dict& d) {
  BatchRow r;
  auto get = [&](const char* key, auto fallback) {
    return d.contains(key) ? d[key].cast<decltype(fallback)>() : fallback;
  };
  r.name = get("name", std::string());
  r.status = get("status", std::string());
  r.error = get("error", std::string());
  r.exit_code = get("exit_code", 0);
  r.input = get("input", std::string());
  r.origin = get("origin", std::string());
  r.key = get("key", std::string());
  r.parts = get("parts", std::size_t{0});
  r.materials = get("materials", std::vector<std::string>());
  r.mass_kg = get("mass_kg", 0.0);
  r.mass_min_kg = get("mass_min_kg", 0.0);
  r.mass_max_kg = get("mass_max_kg", 0.0);
  r.kind = get("kind", std::string());
  r.kind_confidence = get("kind_confidence", 0.0);
  r.mass_in_kind_range = get("mass_in_kind_range", std::string());
  r.seconds = get("seconds", 0.0);
  r.stage_seconds = get("stage_seconds", std::map<std::string, double>());
  r.peak_rss_bytes = static_cast<std::size_t>(get("peak_rss_mib", 0.0) * 1024.0 * 1024.0);
  r.output = get("output", std::string());
  r.finished_at = get("finished_at", std::string());
  return r;
}

py::dict progress_dict(const BatchProgress& p) {
  py::dict d;
  d["total"] = p.total;
  d["done"] = p.done;
  d["failed"] = p.failed;
  d["skipped"] = p.skipped;
  d["running"] = p.running;
  d["elapsed_s"] = p.elapsed_s;
  d["eta_s"] = p.eta_s;
  d["last"] = p.last;
  return d;
}

bool executable(const std::string& path) { return !path.empty() && ::access(path.c_str(), X_OK) == 0; }

// The g2p executable the workers run: tool=, then $G2P_TOOL, then the one
// built beside this module, the installed one, and `g2p` on PATH.
std::string find_tool(const py::object& tool) {
  if (!tool.is_none()) return py::str(tool).cast<std::string>();
  if (const char* env = std::getenv("G2P_TOOL"); env != nullptr && *env != '\0') return env;
  for (const char* candidate : {G2P_PYTHON_BUILD_TOOL, G2P_PYTHON_INSTALLED_TOOL})
    if (executable(candidate)) return candidate;
  if (const char* path = std::getenv("PATH")) {
    std::string dirs = path;
    for (std::size_t start = 0; start <= dirs.size();) {
      const std::size_t end = std::min(dirs.find(':', start), dirs.size());
      const std::string candidate = (fs::path(dirs.substr(start, end - start)) / "g2p").string();
      if (end > start && executable(candidate)) return candidate;
      start = end + 1;
    }
  }
  throw StatusError(Status::NotFound("no g2p executable found: pass tool=PATH or set G2P_TOOL"));
}

std::string fspath(const py::handle& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

// A path or a list of paths (str or os.PathLike) as strings.
std::vector<std::string> strings(const py::object& items, const char* what) {
  std::vector<std::string> out;
  if (items.is_none()) return out;
  if (py::isinstance<py::str>(items) || py::hasattr(items, "__fspath__")) return {fspath(items)};
  for (py::handle item : items) {
    if (!py::isinstance<py::str>(item) && !py::hasattr(item, "__fspath__"))
      throw py::type_error(std::string(what) + " must be strings or paths");
    out.push_back(fspath(item));
  }
  return out;
}

py::object to_dataframe(const py::list& rows) {
  py::module_ pandas;
  try {
    pandas = py::module_::import("pandas");
  } catch (py::error_already_set&) {
    throw py::import_error("g2p.batch_dataframe needs pandas (python3-pandas); the rows are plain dicts without it");
  }
  return pandas.attr("DataFrame")(rows);
}

// ---- Dask -----------------------------------------------------------------------

// What a cluster worker needs to run an asset as run_batch would (no callbacks: it is pickled).
py::dict remote_options(const BatchOptions& o, const py::object& tool) {
  py::dict d;
  d["output_dir"] = o.output_dir;
  d["timeout_s"] = o.timeout_s;
  d["memory_limit_gib"] = o.memory_limit_gib;
  d["kill_grace_s"] = o.kill_grace_s;
  d["options"] = options_file_json(o.run);  // as data: the worker reads it back
  d["tool"] = tool.is_none() ? py::object(py::none()) : py::object(py::str(o.tool));
  return d;
}

// g2p._run_batch_asset: one asset on a cluster worker, in its own process;
// `stop_event` names a distributed.Event that, once set, stops it.
py::dict run_remote(const py::dict& asset, const py::dict& options, const py::object& stop_event) {
  BatchAsset a;
  a.path = asset["path"].cast<std::string>();
  a.name = asset["name"].cast<std::string>();
  a.options = asset["options"].cast<std::string>();
  a.origin = asset["origin"].cast<std::string>();
  BatchOptions o;
  o.tool = find_tool(options["tool"]);  // the worker's own g2p unless the batch named one
  o.output_dir = options["output_dir"].cast<std::string>();
  o.timeout_s = options["timeout_s"].cast<double>();
  o.memory_limit_gib = options["memory_limit_gib"].cast<double>();
  o.kill_grace_s = options["kill_grace_s"].cast<double>();
  o.run = unwrap(parse_options_file(options["options"].cast<std::string>(), "the batch's options"));
  py::object event;
  if (!stop_event.is_none()) event = py::module_::import("distributed").attr("Event")(stop_event);
  auto last_check = std::chrono::steady_clock::now();
  o.stop_requested = [&event, &last_check]() -> int {
    if (!event || std::chrono::steady_clock::now() - last_check < std::chrono::milliseconds(500)) return 0;
    last_check = std::chrono::steady_clock::now();
    py::gil_scoped_acquire gil;
    try {
      return event.attr("is_set")().cast<bool>() ? SIGTERM : 0;
    } catch (py::error_already_set&) {
      return 0;  // the scheduler is out of reach for a moment: keep going
    }
  };
  Result<BatchRow> row = Status::Internal("the asset did not run");
  {
    py::gil_scoped_release release;
    row = run_batch_asset(a, o);
  }
  return row_dict(unwrap(std::move(row)));
}

// Runs each asset as a task on a dask.distributed cluster. Called by
// run_batch on its thread (the GIL released): every call takes the GIL.
class DaskExecutor : public BatchExecutor {
 public:
  DaskExecutor(py::object client, py::dict options) : client_(std::move(client)), options_(std::move(options)) {
    py::module_ distributed = py::module_::import("distributed");
    const std::string id = py::module_::import("uuid").attr("uuid4")().attr("hex").cast<std::string>();
    event_name_ = "g2p-batch-stop-" + id;
    event_ = distributed.attr("Event")(event_name_, py::arg("client") = client_);
    task_ = py::module_::import("g2p").attr("_run_batch_asset_task");
    capacity_ = 0;
    for (auto item : client_.attr("nthreads")().cast<py::dict>()) capacity_ += item.second.cast<std::size_t>();
    capacity_ = std::max<std::size_t>(capacity_, 1);
  }
  ~DaskExecutor() override {
    py::gil_scoped_acquire gil;
    futures_.clear();
    event_ = py::object();
    task_ = py::object();
  }
  std::size_t capacity() const override { return capacity_; }

  Status submit(std::size_t ticket, const BatchAsset& asset) override {
    py::gil_scoped_acquire gil;
    try {
      py::dict a;
      a["path"] = asset.path;
      a["name"] = asset.name;
      a["options"] = asset.options;
      a["origin"] = asset.origin;
      futures_.emplace_back(ticket, client_.attr("submit")(task_, a, options_, event_name_, py::arg("pure") = false,
                                                           py::arg("key") = "g2p-" + asset.name + "-" + event_name_));
    } catch (py::error_already_set& e) {
      return Status::Unavailable("cannot submit " + asset.name + " to the Dask cluster: " + e.what());
    }
    return Status::Ok();
  }

  std::vector<std::pair<std::size_t, BatchRow>> finished() override {
    py::gil_scoped_acquire gil;
    std::vector<std::pair<std::size_t, BatchRow>> done;
    for (auto it = futures_.begin(); it != futures_.end();) {
      if (!it->second.attr("done")().cast<bool>()) {
        ++it;
        continue;
      }
      const std::string status = py::str(it->second.attr("status")).cast<std::string>();
      BatchRow row;
      if (status == "finished") {
        row = row_of_dict(it->second.attr("result")().cast<py::dict>());
      } else if (status == "cancelled") {
        row.status = "cancelled";
        row.error = "cancelled on the cluster";
      } else {  // the task raised, or its worker died (KilledWorker)
        row.status = "failed";
        py::object error = it->second.attr("exception")();
        row.error = "worker error: " + py::str(py::type::of(error).attr("__name__")).cast<std::string>() + ": " +
                    py::str(error).cast<std::string>();
      }
      done.emplace_back(it->first, std::move(row));
      it = futures_.erase(it);
    }
    return done;
  }

  // The running tasks stop their processes when they see the event (within
  // half a second) and come back as "cancelled"; queued ones stop at once.
  void stop(int) override {
    py::gil_scoped_acquire gil;
    try {
      event_.attr("set")();
    } catch (py::error_already_set&) {
      for (auto& [ticket, future] : futures_) future.attr("cancel")();
    }
  }

 private:
  py::object client_;
  py::dict options_;
  std::string event_name_;
  py::object event_, task_;
  std::size_t capacity_ = 1;
  std::vector<std::pair<std::size_t, py::object>> futures_;
};

py::object run(const py::object& inputs, const py::object& output_path, const py::object& manifest, int jobs,
               double timeout, double memory_limit, const py::object& options, const py::object& materials,
               bool retry_failed, const py::object& tool, const py::object& progress, bool dataframe,
               const py::object& client) {
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw py::type_error("progress must be callable (it receives a dict: done, total, failed, eta_s, ...)");
  std::vector<BatchAsset> assets;
  if (!manifest.is_none()) assets = unwrap(read_batch_manifest(fspath(manifest)));
  const std::vector<std::string> listed = strings(inputs, "inputs");
  if (!listed.empty()) {
    std::vector<BatchAsset> more = unwrap(list_batch_inputs(listed));
    assets.insert(assets.end(), more.begin(), more.end());
  }
  if (assets.empty()) throw StatusError(Status::InvalidArgument("g2p.batch: no models: give inputs or manifest"));
  throw_if_error(name_batch_assets(assets));

  BatchOptions o;
  o.tool = find_tool(tool);
  o.output_dir = fspath(output_path);
  o.jobs = jobs;
  o.timeout_s = timeout;
  o.memory_limit_gib = memory_limit;
  if (!options.is_none()) o.run.pipeline = options.cast<PipelineOptions>();
  if (!materials.is_none()) o.run.materials = materials.cast<MaterialTable>();
  o.retry_failed = retry_failed;
  py::object error;  // what the progress callback raised, or KeyboardInterrupt
  o.stop_requested = [&error]() -> int {
    py::gil_scoped_acquire gil;
    if (error) return SIGINT;
    if (PyErr_CheckSignals() != 0) {
      error = py::error_already_set().value();
      return SIGINT;
    }
    return 0;
  };
  if (!progress.is_none())
    o.on_progress = [&progress, &error](const BatchProgress& p) {
      py::gil_scoped_acquire gil;
      if (error) return;
      try {
        progress(progress_dict(p));
      } catch (py::error_already_set& e) {
        error = e.value();
      }
    };
  std::unique_ptr<DaskExecutor> dask;
  if (!client.is_none()) {
    dask = std::make_unique<DaskExecutor>(client, remote_options(o, tool));
    o.executor = dask.get();
  }
  Result<BatchResult> result = Status::Internal("g2p.batch did not run");
  {
    py::gil_scoped_release release;
    result = run_batch(assets, o);
  }
  dask.reset();
  if (error) {
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    throw py::error_already_set();
  }
  const BatchResult r = unwrap(std::move(result));
  py::list rows;
  for (const BatchRow& row : r.rows) rows.append(row_dict(row));
  return dataframe ? to_dataframe(rows) : py::object(rows);
}

}  // namespace

void bind_batch(py::module_& m) {
  m.def("batch", &run, py::arg("inputs"), py::arg("output"), py::kw_only(), py::arg("manifest") = py::none(),
        py::arg("jobs") = 1, py::arg("timeout") = 0.0, py::arg("memory_limit") = 0.0, py::arg("options") = py::none(),
        py::arg("materials") = py::none(), py::arg("retry_failed") = false, py::arg("tool") = py::none(),
        py::arg("progress") = py::none(), py::arg("dataframe") = false, py::arg("client") = py::none(),
        R"(Runs many models through `g2p run`, each in its own worker process, into output/NAME.

inputs: model files, folders (every model file below) or glob patterns; manifest: a CSV or JSON Lines
file with a row per model (path, name, unit, up, segmenter, height, longest_side, object; a JSON
Lines row may add "options"). jobs: worker processes; timeout: seconds per model (0 = none);
memory_limit: GiB per model (0 = none); options: a g2p.PipelineOptions for every model (default
g2p.PipelineOptions()), each row's own over it; materials: a g2p.MaterialTable (default the
paper's). Each model's options reach its `g2p run` as an options file. A crash, hang or out-of-memory in one model is
a row with status "failed" and its cause; the batch goes on. output/index.json and index.csv hold
every row; a rerun skips unchanged models (retry_failed=True reruns the recorded failures).
tool: the g2p executable (default $G2P_TOOL, the built or installed one, or g2p on PATH).
progress: called with a dict (done, total, failed, skipped, running, elapsed_s, eta_s, last).
Returns a list of dicts, one per model, or a pandas DataFrame with dataframe=True.
client: a dask.distributed Client: each model runs as a task on the cluster's workers (in its own
process there, under the same limits; every machine must see the inputs and output at the same
paths and have g2p), as many at a time as the workers have threads; jobs is then ignored.
Ctrl-C stops the running models, writes the index and raises KeyboardInterrupt.)");
  m.def("_run_batch_asset", &run_remote, py::arg("asset"), py::arg("options"), py::arg("stop_event") = py::none(),
        "One asset of a batch on this machine (a Dask worker's task); returns its row.");
  // The task Dask pickles: a Python function of this module, pickled by name
  // (a compiled function is not picklable by value).
  py::dict scope;
  scope["__name__"] = "g2p";
  py::exec(R"(
def _run_batch_asset_task(asset, options, stop_event):
    import g2p
    return g2p._run_batch_asset(asset, options, stop_event)
)",
           scope);
  m.attr("_run_batch_asset_task") = scope["_run_batch_asset_task"];
  m.def(
      "batch_dataframe", [](const py::list& rows) { return to_dataframe(rows); }, py::arg("rows"),
      "The rows of g2p.batch as a pandas DataFrame (needs pandas).");
  m.def(
      "read_batch_index",
      [](const py::object& output) {
        py::list rows;
        for (const BatchRow& row : unwrap(read_batch_index(fspath(output)))) rows.append(row_dict(row));
        return rows;
      },
      py::arg("output"), "The rows of output/index.json (every asset a batch into `output` has run), as dicts.");
}

}  // namespace g2p::python
