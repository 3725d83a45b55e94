// The `g2p` Python module: its exceptions and the binding files in
// dependency order (core types before the stages that use them, stages before
// the pipeline). docs/python.md is the user's guide.
#include <array>

#include "bindings.h"

#if defined(G2P_PYTHON_WITH_CGAL)
#include "g2p/complete_cgal.h"
#endif

namespace g2p::python {

namespace {

constexpr int kNumCodes = static_cast<int>(StatusCode::kOutOfMemory) + 1;

// The exception class of each StatusCode (index = code). Owned by the module
// object; these handles are borrowed for the interpreter's lifetime.
std::array<py::handle, kNumCodes> g_error_classes;

// class NAME(bases...) in module `m`, created through type() because
// pybind11's register_exception takes one base and several of ours have two
// (g2p.Error and ValueError, say).
py::object make_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  py::dict namespace_;
  namespace_["__module__"] = "g2p";
  namespace_["__doc__"] = doc;
  py::object cls =
      py::reinterpret_borrow<py::object>(reinterpret_cast<PyObject*>(&PyType_Type))(name, bases, namespace_);
  m.attr(name) = cls;
  return cls;
}

void bind_errors(py::module_& m) {
  py::object error =
      make_exception(m, "Error", py::make_tuple(py::handle(PyExc_RuntimeError)),
                     "A libg2p operation failed. str(e) is the library's full message; e.code is the g2p.StatusCode.");
  auto sub = [&](StatusCode code, const char* name, py::handle extra, const char* doc) {
    py::tuple bases = extra ? py::make_tuple(error, extra) : py::make_tuple(error);
    g_error_classes[static_cast<int>(code)] = make_exception(m, name, bases, doc).inc_ref();
  };
  g_error_classes[0] = py::handle(error).inc_ref();  // never raised for kOk; the fallback slot
  sub(StatusCode::kInvalidArgument, "InvalidArgumentError", PyExc_ValueError,
      "The caller passed something unusable (options, a mesh, a setting).");
  sub(StatusCode::kNotFound, "NotFoundError", PyExc_LookupError, "A file, class or backend name that does not exist.");
  sub(StatusCode::kIoError, "IoError", py::handle(), "Reading or writing failed at the operating-system level.");
  sub(StatusCode::kParseError, "ParseError", PyExc_ValueError, "A file exists but its content is malformed.");
  sub(StatusCode::kUnsupported, "UnsupportedError", PyExc_NotImplementedError,
      "A valid request this build or format cannot serve.");
  sub(StatusCode::kCancelled, "Cancelled", py::handle(), "The run was cancelled (RunContext.cancel, progress).");
  sub(StatusCode::kUnavailable, "UnavailableError", py::handle(),
      "An optional service (network, model) could not be reached.");
  sub(StatusCode::kInternal, "InternalError", py::handle(), "A bug or an unexpected failure inside libg2p.");
  sub(StatusCode::kOutOfMemory, "OutOfMemoryError", PyExc_MemoryError,
      "The work needs more memory than the limit (PipelineOptions.memory_limit_bytes) or the machine has.");

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const StatusError& e) {
      set_python_error(e.status());
    }
  });
}

}  // namespace

void set_python_error(const Status& status) {
  const int code = static_cast<int>(status.code());
  py::handle cls = g_error_classes[code >= 0 && code < kNumCodes ? code : 0];
  py::object exception = cls(status.message());
  exception.attr("code") = py::cast(status.code());
  PyErr_SetObject(cls.ptr(), exception.ptr());
}

Status status_from_python(const py::error_already_set& error, const std::string& where) {
  StatusCode code = StatusCode::kInternal;
  py::object value = error.value();
  if (error.matches(PyExc_KeyboardInterrupt)) {
    code = StatusCode::kCancelled;
  } else if (error.matches(g_error_classes[0]) && py::hasattr(value, "code")) {
    try {
      code = value.attr("code").cast<StatusCode>();
    } catch (const py::cast_error&) {
      code = StatusCode::kInternal;
    }
    if (code == StatusCode::kOk) code = StatusCode::kInternal;
  }
  std::string text;
  try {
    py::object lines = py::module_::import("traceback").attr("format_exception")(error.type(), value, error.trace());
    text = py::str("").attr("join")(lines).cast<std::string>();
  } catch (const py::error_already_set&) {
    text = error.what();  // formatting failed (interpreter shutting down): pybind11's own summary
  }
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return {code, where + " raised a Python exception:\n" + text};
}

bool has_integer_dtype(const py::array& array) {
  const char kind = array.dtype().kind();
  return kind == 'i' || kind == 'u';
}

std::vector<int> int_vector_from_numpy(const py::handle& object, const std::string& what) {
  py::array any = py::array::ensure(object);
  if (!any) throw py::type_error(what + ": expected a 1-D integer array");
  if (any.size() > 0 && !has_integer_dtype(any))
    throw py::type_error(what + ": expected an integer dtype, got " + std::string(py::str(any.dtype())));
  if (any.ndim() != 1)
    throw py::value_error(what + ": expected a 1-D array, got " + std::to_string(any.ndim()) + " dimensions");
  auto array = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(any);
  return std::vector<int>(array.data(), array.data() + array.size());
}

void bind_eval(py::module_& m);  // eval.cpp: ConfusionMatrix, evaluate_segmentation, mass errors

}  // namespace g2p::python

PYBIND11_MODULE(g2p, m) {
  namespace py = pybind11;
  using namespace g2p::python;
  m.doc() =
      "Gen2Physics (libg2p): static 3D meshes to simulation-ready, per-material physical parts. "
      "See docs/python.md.";
  m.attr("__version__") = g2p::version();

  // StatusCode first: the exceptions carry it.
  py::enum_<g2p::StatusCode>(m, "StatusCode", "Why a libg2p operation failed (g2p.Error.code).")
      .value("OK", g2p::StatusCode::kOk)
      .value("INVALID_ARGUMENT", g2p::StatusCode::kInvalidArgument)
      .value("NOT_FOUND", g2p::StatusCode::kNotFound)
      .value("IO_ERROR", g2p::StatusCode::kIoError)
      .value("PARSE_ERROR", g2p::StatusCode::kParseError)
      .value("UNSUPPORTED", g2p::StatusCode::kUnsupported)
      .value("CANCELLED", g2p::StatusCode::kCancelled)
      .value("UNAVAILABLE", g2p::StatusCode::kUnavailable)
      .value("INTERNAL", g2p::StatusCode::kInternal)
      .value("OUT_OF_MEMORY", g2p::StatusCode::kOutOfMemory);
  bind_errors(m);

  bind_core(m);
  bind_stage_types(m);
  bind_stages(m);
  bind_decompose(m);
  bind_pipeline(m);
  bind_batch(m);
  bind_eval(m);

#if defined(G2P_PYTHON_WITH_CGAL)
  // The GPL component is linked into this module: its completers ("alpha-wrap",
  // "fill") are available by name as in the g2p tool.
  throw_if_error(g2p::register_cgal_completers());
  m.attr("with_cgal") = true;
#else
  m.attr("with_cgal") = false;
#endif
}
