// Private glue shared by the translation units of the `g2p` Python module:
// Status <-> exception, numpy <-> Image and Mesh arrays, and the binding
// entry points of each file. Declared once here so that every file sees the
// same opaque types (pybind11 requires it).
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl_bind.h>

#include <Eigen/Core>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "g2p/g2p.h"

// Backend settings stay a C++ map that Python edits in place
// (`options.segmenter.settings["model"] = "x.onnx"`); a converted dict would
// be a copy and the assignment would be lost silently.
PYBIND11_MAKE_OPAQUE(g2p::BackendSettings)

namespace g2p::python {

namespace py = pybind11;

// ---- Status and exceptions -----------------------------------------------------

// A failed Status on its way to Python; the module's translator turns it into
// the g2p.Error subclass of its code.
class StatusError : public std::exception {
 public:
  explicit StatusError(Status status) : status_(std::move(status)) {}
  const Status& status() const { return status_; }
  const char* what() const noexcept override { return status_.message().c_str(); }

 private:
  Status status_;
};

inline void throw_if_error(const Status& status) {
  if (!status.ok()) throw StatusError(status);
}

template <typename T>
T unwrap(Result<T>&& result) {
  if (!result.ok()) throw StatusError(result.status());
  return std::move(*result);
}

// Sets the Python error for `status` (the g2p.Error subclass of its code,
// with `code` and the full message). Defined in module.cpp.
void set_python_error(const Status& status);

// The Status a Python exception becomes when it leaves a trampoline: a
// g2p.Error keeps its code, KeyboardInterrupt becomes kCancelled, anything
// else kInternal. The message is `where` plus the formatted traceback.
// Needs the GIL; clears nothing (error_already_set already fetched it).
Status status_from_python(const py::error_already_set& error, const std::string& where);

// ---- Lifetime of Python objects held by C++ --------------------------------------

// A shared_ptr to the C++ part of a Python object that also keeps the Python
// object alive: a subclass created inline (`p.set_segmenter(MySeg())`) keeps
// its overrides and __dict__ for as long as C++ holds it. The Python reference
// is dropped with the GIL held.
template <typename T>
std::shared_ptr<T> hold_python_object(py::object object) {
  if (object.is_none()) return nullptr;
  std::shared_ptr<T> cpp = object.cast<std::shared_ptr<T>>();
  auto* keeper = new py::object(std::move(object));
  T* raw = cpp.get();
  return std::shared_ptr<T>(raw, [keeper, cpp](T*) mutable {
    if (!Py_IsInitialized()) return;  // interpreter gone: leak rather than crash
    py::gil_scoped_acquire gil;
    delete keeper;
    cpp.reset();
  });
}

// The Python class name of the object behind `self` (for messages).
template <typename Base>
std::string python_class_name(const Base* self) {
  py::object object = py::cast(self, py::return_value_policy::reference);
  return py::str(py::type::handle_of(object).attr("__qualname__"));
}

// ---- numpy -----------------------------------------------------------------------

// An image as a new numpy array: (H, W) when `squeeze` and single-channel,
// else (H, W, C); None when empty.
template <typename T>
py::object image_to_numpy(const Image<T>& image, bool squeeze) {
  if (image.empty()) return py::none();
  std::vector<py::ssize_t> shape{image.height(), image.width()};
  if (!(squeeze && image.channels() == 1)) shape.push_back(image.channels());
  py::array_t<T> array(shape);
  std::memcpy(array.mutable_data(), image.data(), image.size() * sizeof(T));
  return std::move(array);
}

// A numpy array (H, W) or (H, W, C) as an image; None gives an empty image.
// `channels` > 0 requires that many. `what` names the buffer in errors.
template <typename T>
Image<T> image_from_numpy(const py::handle& object, int channels, const std::string& what) {
  if (object.is_none()) return {};
  auto array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!array) throw py::type_error(what + ": expected a numpy array");
  if (array.ndim() != 2 && array.ndim() != 3)
    throw py::value_error(what + ": expected shape (height, width) or (height, width, channels), got " +
                          std::to_string(array.ndim()) + " dimensions");
  const int c = array.ndim() == 3 ? static_cast<int>(array.shape(2)) : 1;
  if (channels > 0 && c != channels)
    throw py::value_error(what + ": expected " + std::to_string(channels) + " channel(s), got " + std::to_string(c));
  if (c < 1) throw py::value_error(what + ": an image needs at least one channel");
  Image<T> image(static_cast<int>(array.shape(1)), static_cast<int>(array.shape(0)), c);
  std::memcpy(image.data(), array.data(), image.size() * sizeof(T));
  return image;
}

// Rows of fixed-size Eigen vectors as an (N, Cols) array of `Out`.
template <typename Out, typename Vec>
py::array_t<Out> rows_to_numpy(const std::vector<Vec>& rows) {
  constexpr int kCols = Vec::RowsAtCompileTime;
  py::array_t<Out> array({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(kCols)});
  Out* out = array.mutable_data();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int c = 0; c < kCols; ++c) out[i * kCols + c] = static_cast<Out>(rows[i][c]);
  return array;
}

// An (N, Cols) array as rows of Eigen vectors; None gives no rows.
template <typename Vec>
std::vector<Vec> rows_from_numpy(const py::handle& object, const std::string& what) {
  using Scalar = typename Vec::Scalar;
  constexpr int kCols = Vec::RowsAtCompileTime;
  if (object.is_none()) return {};
  auto array = py::array_t<Scalar, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!array) throw py::type_error(what + ": expected an array of shape (N, " + std::to_string(kCols) + ")");
  if (array.ndim() != 2 || array.shape(1) != kCols)
    throw py::value_error(what + ": expected shape (N, " + std::to_string(kCols) + "), got " +
                          std::string(py::str(py::getattr(array, "shape"))));
  std::vector<Vec> rows(static_cast<std::size_t>(array.shape(0)));
  const Scalar* in = array.data();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int c = 0; c < kCols; ++c) rows[i][c] = in[i * kCols + c];
  return rows;
}

template <typename T>
py::array_t<T> vector_to_numpy(const std::vector<T>& values) {
  py::array_t<T> array(static_cast<py::ssize_t>(values.size()));
  if (!values.empty()) std::memcpy(array.mutable_data(), values.data(), values.size() * sizeof(T));
  return array;
}

// A 1-D integer array (any integer dtype; floats are refused rather than
// truncated) as a vector.
std::vector<int> int_vector_from_numpy(const py::handle& object, const std::string& what);

// Dense (faces, classes) vote histograms; rows of unseen faces are zero.
py::array_t<float> dense_votes(const FaceVotes& votes);

// Whether a numpy array's dtype is an integer type.
bool has_integer_dtype(const py::array& array);

// ---- Keyword construction of option structs ----------------------------------------

// Builds a T from keyword arguments by setting its Python attributes, so
// every bound field is a keyword (`g2p.ViewOptions(num_views=6)`); unknown
// names are a TypeError that names them.
template <typename T>
T from_kwargs(const py::kwargs& kwargs) {
  py::object object = py::cast(T{});
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first);
    if (key.empty() || key[0] == '_' || !py::hasattr(object, key.c_str()))
      throw py::type_error(std::string(py::str(py::type::handle_of(object).attr("__name__"))) +
                           "() got an unexpected keyword argument '" + key + "'");
    py::setattr(object, item.first, item.second);
  }
  return object.cast<T>();
}

// ---- Per-file binding functions ------------------------------------------------------

// Backend settings from Python: a dict (or BackendSettings) and keyword
// arguments, each value as --set writes it (True -> "on", 0.5 -> "0.5").
BackendSettings settings_from_python(const py::handle& settings, const py::kwargs& kwargs);
// A backend's described settings as a list of dicts (key, type, unit, range,
// value, help).
py::list settings_to_python(const std::vector<SettingInfo>& info);

void bind_core(py::module_& m);         // core.cpp: errors' enums, Mesh, Model, materials, io
void bind_stage_types(py::module_& m);  // stage_types.cpp: cameras, views, label maps, parts, results
void bind_stages(py::module_& m);       // stages.cpp: the stage interfaces, registries, stage functions
void bind_decompose(py::module_& m);    // decompose.cpp: options, results, Decomposer, convex_hull
void bind_pipeline(py::module_& m);     // pipeline.cpp: options, RunContext, Pipeline, PipelineResult
void bind_batch(py::module_& m);        // batch.cpp: g2p.batch, its rows and DataFrame

}  // namespace g2p::python
