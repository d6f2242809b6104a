// numpy <-> Eigen, JSON -> Python, and the error translation of the Python module (convert.h).
#include "convert.h"

#include "vertexflow/io.h"

#include <cmath>

namespace vertexflow::python {

py::array as_numeric_array(const py::handle& object, const char* name) {
  py::array a = py::array::ensure(object);
  if (!a)
    throw py::value_error(std::string(name) + " must be a numeric array, got " +
                          std::string(py::str(py::type::handle_of(object).attr("__name__"))));
  const char kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::value_error(std::string(name) + " must be a numeric array, got dtype " + std::string(py::str(a.dtype())));
  return a;
}

DoubleArray as_vertices(const py::handle& object, const char* name) {
  py::array a = as_numeric_array(object, name);
  DoubleArray v = DoubleArray::ensure(a);
  if (!v) throw py::error_already_set();
  if (v.ndim() != 2 || v.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (n, 3), got " +
                          std::string(py::str(py::getattr(v, "shape"))));
  if (v.shape(0) == 0) throw py::value_error(std::string(name) + " is empty (no vertices)");
  const double* data = v.data();
  for (py::ssize_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(data[i]))
      throw py::value_error(std::string(name) + " has a non-finite coordinate (row " + std::to_string(i / 3) + ")");
  return v;
}

Int64Array as_faces(const py::handle& object, py::ssize_t num_vertices, const char* name) {
  py::array a = as_numeric_array(object, name);
  if (a.dtype().kind() == 'f') {
    const DoubleArray d = DoubleArray::ensure(a);
    for (py::ssize_t i = 0; i < d.size(); ++i)
      if (d.data()[i] != std::floor(d.data()[i]))
        throw py::value_error(std::string(name) + " must hold vertex indices (integers), got " +
                              std::to_string(d.data()[i]));
  }
  Int64Array f = Int64Array::ensure(a);
  if (!f) throw py::error_already_set();
  if (f.ndim() != 2 || f.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (m, 3) (triangles), got " +
                          std::string(py::str(py::getattr(f, "shape"))));
  if (f.shape(0) == 0) throw py::value_error(std::string(name) + " is empty (no faces)");
  const std::int64_t* data = f.data();
  for (py::ssize_t i = 0; i < f.size(); ++i)
    if (data[i] < 0 || data[i] >= num_vertices)
      throw py::value_error(std::string(name) + " has vertex index " + std::to_string(data[i]) + " (row " +
                            std::to_string(i / 3) + ") outside [0, " + std::to_string(num_vertices) + ")");
  return f;
}

Vertices to_vertices(const DoubleArray& v) {
  return Eigen::Map<const Vertices>(v.data(), v.shape(0), 3);
}

Faces to_faces(const Int64Array& f) {
  return Eigen::Map<const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 3, Eigen::RowMajor>>(f.data(), f.shape(0), 3)
      .cast<Index>();
}

Mesh to_mesh(const py::handle& V, const py::handle& F, const char* v_name, const char* f_name) {
  const DoubleArray v = as_vertices(V, v_name);
  const Int64Array f = as_faces(F, v.shape(0), f_name);
  Mesh mesh;
  mesh.V = to_vertices(v);
  mesh.F = to_faces(f);
  return mesh;
}

py::tuple mesh_tuple(Mesh&& mesh) {
  return py::make_tuple(to_numpy(std::move(mesh.V)), to_numpy(std::move(mesh.F)));
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& item : j) list.append(to_python(item));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, value] : j.items()) dict[py::str(key)] = to_python(value);
      return dict;
    }
    default:
      return py::none();
  }
}

std::vector<std::string> string_lines(const py::object& lines, const char* what) {
  std::vector<std::string> out;
  if (lines.is_none()) return out;
  if (py::isinstance<py::str>(lines) || !py::isinstance<py::sequence>(lines))
    throw py::value_error(std::string(what) + " must be a sequence of str (one per line)");
  for (const py::handle item : lines) {
    if (!py::isinstance<py::str>(item)) throw py::value_error(std::string(what) + " must be a sequence of str");
    out.push_back(item.cast<std::string>());
  }
  return out;
}

std::string fspath(const py::handle& path) {
  // Leaked on purpose: a static py::object would be released after the interpreter is gone.
  static const py::handle os_fspath = py::object(py::module_::import("os").attr("fspath")).release();
  return py::str(os_fspath(path)).cast<std::string>();
}

void check_threads(int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores), got " + std::to_string(threads));
}

void register_exception_translators() {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
}

}  // namespace vertexflow::python
