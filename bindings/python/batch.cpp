// g2p.batch: many models, each through `g2p run` in its own worker process
// (g2p::run_batch, with the GIL released), the index as rows (dicts) or a
// pandas DataFrame. Ctrl-C stops the batch cleanly and raises KeyboardInterrupt.
#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

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
  d["seconds"] = r.seconds;
  d["stage_seconds"] = r.stage_seconds;
  d["peak_rss_mib"] = static_cast<double>(r.peak_rss_bytes) / (1024.0 * 1024.0);
  d["output"] = r.output;
  d["finished_at"] = r.finished_at;
  return d;
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

py::object run(const py::object& inputs, const py::object& output_path, const py::object& manifest, int jobs,
               double timeout, double memory_limit, const py::object& run_args, bool retry_failed,
               const py::object& tool, const py::object& progress, bool dataframe) {
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
  o.run_args = strings(run_args, "run_args");
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
  Result<BatchResult> result = Status::Internal("g2p.batch did not run");
  {
    py::gil_scoped_release release;
    result = run_batch(assets, o);
  }
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
        py::arg("jobs") = 1, py::arg("timeout") = 0.0, py::arg("memory_limit") = 0.0, py::arg("run_args") = py::none(),
        py::arg("retry_failed") = false, py::arg("tool") = py::none(), py::arg("progress") = py::none(),
        py::arg("dataframe") = false,
        R"(Runs many models through `g2p run`, each in its own worker process, into output/NAME.

inputs: model files, folders (every model file below) or glob patterns; manifest: a CSV or JSON Lines
file with a row per model (path, name, unit, up, segmenter, height, longest_side). jobs: worker
processes; timeout: seconds per model (0 = none); memory_limit: GiB per model (0 = none); run_args:
`g2p run` flags for every model (["--views", "6"]). A crash, hang or out-of-memory in one model is
a row with status "failed" and its cause; the batch goes on. output/index.json and index.csv hold
every row; a rerun skips unchanged models (retry_failed=True reruns the recorded failures).
tool: the g2p executable (default $G2P_TOOL, the built or installed one, or g2p on PATH).
progress: called with a dict (done, total, failed, skipped, running, elapsed_s, eta_s, last).
Returns a list of dicts, one per model, or a pandas DataFrame with dataframe=True.
Ctrl-C stops the running models, writes the index and raises KeyboardInterrupt.)");
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
