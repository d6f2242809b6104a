// What every file of the Python module vertexflow._core shares: numpy arrays <-> Eigen, JSON ->
// Python, the GIL and thread-count helper, and the translation of library errors.
//
// Conventions (the docstrings and the stub repeat them for Python users)
// - Input arrays go through as_vertices / as_faces: V is converted to C-contiguous float64 only
//   when it is not already (numpy returns the same object then: no copy), F to integers in
//   range. Bad arrays raise ValueError naming the argument and the problem.
// - Library errors keep their C++ message: IoError -> OSError, std::invalid_argument ->
//   ValueError (pybind11's own translation), other std::exception -> RuntimeError.
// - Every heavy call releases the GIL while the library works, and takes `threads`: 0 (the
//   default) uses every core, n > 0 runs the call in a TBB task_arena of n threads (results do
//   not depend on it).
// - Nothing is printed: progress goes to the optional `progress` callable.
#pragma once

#include "vertexflow/mesh.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vertexflow::python {

namespace py = pybind11;

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int64Array = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

/// `object` as a numpy array of a numeric dtype (integer or float); ValueError naming `name`
/// otherwise.
py::array as_numeric_array(const py::handle& object, const char* name);

/// V as a C-contiguous float64 (n, 3) array with n > 0 and finite values: the same object when
/// it is one already.
DoubleArray as_vertices(const py::handle& object, const char* name = "V");

/// F as an int64 (m, 3) array with m > 0 and every index in [0, num_vertices): the same object
/// when it is C-contiguous int64 already; float arrays must hold integers.
Int64Array as_faces(const py::handle& object, py::ssize_t num_vertices, const char* name = "F");

Vertices to_vertices(const DoubleArray& v);
Faces to_faces(const Int64Array& f);

/// (V, F) checked (as_vertices, as_faces) and copied into a Mesh, no comments.
Mesh to_mesh(const py::handle& V, const py::handle& F, const char* v_name = "V", const char* f_name = "F");

/// A numpy array that owns `matrix` (moved to the heap, freed with the array): no copy.
template <typename Matrix>
py::array to_numpy(Matrix&& matrix) {
  using M = std::decay_t<Matrix>;
  using Scalar = typename M::Scalar;
  auto* heap = new M(std::forward<Matrix>(matrix));
  py::capsule owner(heap, [](void* p) { delete static_cast<M*>(p); });
  const auto s = static_cast<py::ssize_t>(sizeof(Scalar));
  if constexpr (M::ColsAtCompileTime == 1) {
    return py::array_t<Scalar>({static_cast<py::ssize_t>(heap->rows())}, {s}, heap->data(), owner);
  } else {
    static_assert(M::IsRowMajor, "row-major matrices only");
    return py::array_t<Scalar>({static_cast<py::ssize_t>(heap->rows()), static_cast<py::ssize_t>(heap->cols())},
                               {s * static_cast<py::ssize_t>(heap->cols()), s}, heap->data(), owner);
  }
}

/// (V, F) of `mesh` as numpy arrays, without copies.
py::tuple mesh_tuple(Mesh&& mesh);

/// MeshAttributes as the Python dict the module uses (vertexflow.MeshAttributes): {"vertex": [channel],
/// "corner": [channel with "corners"], "face": [channel], "materials", "groups", "objects",
/// "material_libraries": [str]}, each channel {"name", "components", "type", "role", "values"}
/// with values a (rows, width) float64 array and corners an (m, 3) int32 array. Moves the
/// matrices into the arrays (no copies). The glTF document (MeshAttributes::gltf) is left out:
/// it has no Python form.
py::dict attributes_to_python(MeshAttributes&& attributes);

/// The dict (or None: no attributes) as MeshAttributes for a mesh of `num_vertices` and
/// `num_faces`: every key checked (unknown keys, missing ones, shapes, types, roles, integer
/// values in their type's range), then MeshAttributes::validate. ValueError naming the key
/// ("attributes['corner'][0]['values']: ...") or, from validate, the channel.
MeshAttributes attributes_from_python(const py::handle& object, std::int64_t num_vertices, std::int64_t num_faces,
                                      const char* name = "attributes");

/// JSON as Python values: objects as dicts, arrays as lists, null as None.
py::object to_python(const nlohmann::json& j);

/// A sequence of str (not a str itself, which would read as one line per character); None gives
/// no lines. ValueError naming `what` otherwise.
std::vector<std::string> string_lines(const py::object& lines, const char* what);

/// os.fspath(path) as a string: str and os.PathLike alike.
std::string fspath(const py::handle& path);

/// The enumerator named `name` in `names`; ValueError listing the names otherwise.
template <typename Enum>
Enum enum_option(const std::string& key, const std::string& name, const std::map<std::string, Enum>& names) {
  const auto it = names.find(name);
  if (it != names.end()) return it->second;
  std::string allowed;
  for (const auto& entry : names) allowed += (allowed.empty() ? "" : ", ") + entry.first;
  throw py::value_error("option " + key + ": '" + name + "' is not one of " + allowed);
}

/// ValueError unless threads >= 0.
void check_threads(int threads);

/// Runs `work` without the GIL, in a task_arena of `threads` TBB threads (0: all cores).
template <typename Work>
auto without_gil(int threads, Work&& work) {
  check_threads(threads);
  py::gil_scoped_release release;
  if (threads > 0) {
    tbb::task_arena arena(threads);
    return arena.execute(std::forward<Work>(work));
  }
  return work();
}

/// IoError -> OSError (std::invalid_argument -> ValueError is pybind11's own).
void register_exception_translators();

/// One per file: the functions of each topic.
void register_io(py::module_& m);
void register_enhance(py::module_& m);
void register_metrics(py::module_& m);
void register_remesh(py::module_& m);
void register_render_lines(py::module_& m);
void register_batch(py::module_& m);
void register_lod(py::module_& m);

}  // namespace vertexflow::python
