// numpy <-> Eigen, JSON -> Python, and the error translation of the Python module (convert.h).
#include "convert.h"

#include "vertexflow/io.h"
#include "vertexflow/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>

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

namespace {

// The first entry of `a` (integers, or floats already known to be whole) outside [low, high):
// the value as given, as text, and its flat position. Checked in the array's own dtype before
// any cast to int64, which would wrap a uint64 above 2^63 - 1 (2^64 - 1 read as -1) and make a
// float beyond int64 any value at all.
std::optional<std::pair<std::string, py::ssize_t>> first_outside(const py::array& a, std::int64_t low,
                                                                 std::int64_t high) {
  const char kind = a.dtype().kind();
  if (kind == 'u') {
    const auto u = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    if (!u) throw py::error_already_set();
    for (py::ssize_t i = 0; i < u.size(); ++i)
      if (static_cast<std::int64_t>(std::min<std::uint64_t>(u.data()[i], INT64_MAX)) < low ||
          u.data()[i] >= static_cast<std::uint64_t>(std::max<std::int64_t>(high, 0)))
        return std::make_pair(std::to_string(u.data()[i]), i);
  } else if (kind == 'f') {
    const DoubleArray d = DoubleArray::ensure(a);
    if (!d) throw py::error_already_set();
    for (py::ssize_t i = 0; i < d.size(); ++i)
      if (!(d.data()[i] >= static_cast<double>(low) && d.data()[i] < static_cast<double>(high)))
        return std::make_pair(py::repr(py::float_(d.data()[i])).cast<std::string>(), i);
  } else {
    const Int64Array v = Int64Array::ensure(a);
    if (!v) throw py::error_already_set();
    for (py::ssize_t i = 0; i < v.size(); ++i)
      if (v.data()[i] < low || v.data()[i] >= high) return std::make_pair(std::to_string(v.data()[i]), i);
  }
  return std::nullopt;
}

}  // namespace

Int64Array as_faces(const py::handle& object, py::ssize_t num_vertices, const char* name) {
  py::array a = as_numeric_array(object, name);
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + " must have shape (m, 3) (triangles), got " +
                          std::string(py::str(py::getattr(a, "shape"))));
  if (a.shape(0) == 0) throw py::value_error(std::string(name) + " is empty (no faces)");
  if (a.dtype().kind() == 'f') {
    const DoubleArray d = DoubleArray::ensure(a);
    for (py::ssize_t i = 0; i < d.size(); ++i)
      if (d.data()[i] != std::floor(d.data()[i]))
        throw py::value_error(std::string(name) + " must hold vertex indices (integers), got " +
                              std::to_string(d.data()[i]));
  }
  if (const auto bad = first_outside(a, 0, num_vertices))
    throw py::value_error(std::string(name) + " has vertex index " + bad->first + " (row " +
                          std::to_string(bad->second / 3) + ") outside [0, " + std::to_string(num_vertices) + ")");
  Int64Array f = Int64Array::ensure(a);
  if (!f) throw py::error_already_set();
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

namespace {

constexpr int kScalarTypes = 8;  // ScalarType's enumerators, Int8 .. Float64
constexpr int kRoles = 6;        // AttributeRole's, Generic .. Weights

py::list string_list(const std::vector<std::string>& strings) {
  py::list list;
  for (const std::string& s : strings) list.append(py::str(s));
  return list;
}

py::dict channel_to_python(AttributeChannel&& channel) {
  py::dict d;
  d["name"] = py::str(channel.name);
  d["components"] = string_list(channel.components);
  d["type"] = py::str(scalar_type_name(channel.type));
  d["role"] = py::str(attribute_role_name(channel.role));
  d["values"] = to_numpy(std::move(channel.values));
  return d;
}

std::string key_of(const std::string& parent, const std::string& key) {
  return parent + "['" + key + "']";
}

std::string item_of(const std::string& parent, std::size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

// `object` as a dict whose keys are all in `allowed`; ValueError naming the first other key.
py::dict checked_dict(const py::handle& object, const std::string& name, std::initializer_list<const char*> allowed) {
  if (!py::isinstance<py::dict>(object))
    throw py::value_error(name + " must be a dict, got " +
                          std::string(py::str(py::type::handle_of(object).attr("__name__"))));
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  for (const auto& [key, value] : d) {
    const std::string k = py::str(key);
    bool known = false;
    std::string keys;
    for (const char* a : allowed) {
      known = known || k == a;
      keys += (keys.empty() ? "" : ", ") + std::string(a);
    }
    if (!known) throw py::value_error(name + ": unknown key '" + k + "' (the keys are " + keys + ")");
  }
  return d;
}

// A sequence of items (not a str), or an empty one for a missing key or None.
std::vector<py::handle> sequence_items(const py::dict& d, const char* key, const std::string& name) {
  std::vector<py::handle> items;
  if (!d.contains(key) || d[key].is_none()) return items;
  const py::object value = d[key];
  if (py::isinstance<py::str>(value) || !py::isinstance<py::sequence>(value))
    throw py::value_error(name + " must be a list");
  for (const py::handle item : value) items.push_back(item);
  return items;
}

std::string str_value(const py::dict& d, const char* key, const std::string& name) {
  if (!d.contains(key)) throw py::value_error(name + " is missing");
  const py::object value = d[key];
  if (!py::isinstance<py::str>(value)) throw py::value_error(name + " must be a str");
  return value.cast<std::string>();
}

// The enumerator whose name (`name_of`) is `text`; ValueError listing the names otherwise.
template <typename Enum>
Enum named_enum(const std::string& text, int count, const char* (*name_of)(Enum), const std::string& name) {
  std::string names;
  for (int i = 0; i < count; ++i) {
    const auto e = static_cast<Enum>(i);
    if (text == name_of(e)) return e;
    names += (names.empty() ? "" : ", ") + std::string(name_of(e));
  }
  throw py::value_error(name + ": '" + text + "' is not one of " + names);
}

AttributeChannel channel_from_python(const py::handle& object, const std::string& name, bool corner) {
  const py::dict d = corner ? checked_dict(object, name, {"name", "components", "type", "role", "values", "corners"})
                            : checked_dict(object, name, {"name", "components", "type", "role", "values"});
  AttributeChannel c;
  c.name = str_value(d, "name", key_of(name, "name"));
  if (d.contains("type"))
    c.type =
        named_enum(str_value(d, "type", key_of(name, "type")), kScalarTypes, &scalar_type_name, key_of(name, "type"));
  if (d.contains("role"))
    c.role = named_enum(str_value(d, "role", key_of(name, "role")), kRoles, &attribute_role_name, key_of(name, "role"));

  const std::string values_name = key_of(name, "values");
  if (!d.contains("values")) throw py::value_error(values_name + " is missing");
  const DoubleArray values = DoubleArray::ensure(as_numeric_array(d["values"], values_name.c_str()));
  if (!values) throw py::error_already_set();
  if (values.ndim() != 1 && values.ndim() != 2)
    throw py::value_error(values_name + " must have shape (rows, components), got " +
                          std::string(py::str(py::getattr(values, "shape"))));
  const py::ssize_t rows = values.shape(0), width = values.ndim() == 2 ? values.shape(1) : 1;
  if (width == 0) throw py::value_error(values_name + " has no columns");
  c.values = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(values.data(),
                                                                                                      rows, width);
  if (is_integer_type(c.type)) {
    for (Eigen::Index i = 0; i < c.values.size(); ++i) {
      const double v = c.values.data()[i];
      if (to_scalar_type(v, c.type) != v)
        throw py::value_error(values_name + " has " + py::str(py::float_(v)).cast<std::string>() + " (row " +
                              std::to_string(i / width) + "), not an integer that " + scalar_type_name(c.type) +
                              " holds");
    }
  }

  const std::string components_name = key_of(name, "components");
  if (d.contains("components") && !d["components"].is_none()) {
    c.components = string_lines(d["components"], components_name.c_str());
    if (static_cast<py::ssize_t>(c.components.size()) != width)
      throw py::value_error(components_name + " names " + std::to_string(c.components.size()) + " components for " +
                            std::to_string(width) + " columns of values");
  } else if (width == 1) {
    c.components = {c.name};
  } else {
    throw py::value_error(components_name + " is missing (needed for " + std::to_string(width) + " columns)");
  }
  return c;
}

CornerChannel corner_from_python(const py::handle& object, const std::string& name, std::int64_t num_faces) {
  CornerChannel c;
  c.channel = channel_from_python(object, name, true);
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  const std::string corners_name = key_of(name, "corners");
  if (!d.contains("corners")) throw py::value_error(corners_name + " is missing");
  const py::array a = as_numeric_array(d["corners"], corners_name.c_str());
  if (a.dtype().kind() == 'f') {
    const DoubleArray f = DoubleArray::ensure(a);
    for (py::ssize_t i = 0; i < f.size(); ++i)
      if (f.data()[i] != std::floor(f.data()[i]))
        throw py::value_error(corners_name + " must hold row indices (integers), got " + std::to_string(f.data()[i]));
  }
  if (a.ndim() != 2 || a.shape(1) != 3 || a.shape(0) != num_faces)
    throw py::value_error(corners_name + " must have shape (" + std::to_string(num_faces) +
                          ", 3) (one row per face), got " + std::string(py::str(py::getattr(a, "shape"))));
  const std::int64_t rows = c.channel.rows();
  // In the array's own dtype: a uint64 2^64 - 1 cast to int64 would read as -1, "none".
  if (const auto bad = first_outside(a, -1, rows))
    throw py::value_error(corners_name + " has " + bad->first + " (row " + std::to_string(bad->second / 3) +
                          ") outside -1.." + std::to_string(rows - 1) + " (the rows of its values; -1: none)");
  const Int64Array corners = Int64Array::ensure(a);
  if (!corners) throw py::error_already_set();
  c.corners = Eigen::Map<const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 3, Eigen::RowMajor>>(corners.data(),
                                                                                                corners.shape(0), 3)
                  .cast<std::int32_t>();
  return c;
}

}  // namespace

py::dict attributes_to_python(MeshAttributes&& attributes) {
  py::dict d;
  py::list vertex, corner, face;
  for (AttributeChannel& c : attributes.vertex) vertex.append(channel_to_python(std::move(c)));
  for (CornerChannel& c : attributes.corner) {
    py::dict channel = channel_to_python(std::move(c.channel));
    channel["corners"] = to_numpy(std::move(c.corners));
    corner.append(channel);
  }
  for (AttributeChannel& c : attributes.face) face.append(channel_to_python(std::move(c)));
  d["vertex"] = vertex;
  d["corner"] = corner;
  d["face"] = face;
  d["materials"] = string_list(attributes.materials);
  d["groups"] = string_list(attributes.groups);
  d["objects"] = string_list(attributes.objects);
  d["material_libraries"] = string_list(attributes.material_libraries);
  return d;
}

MeshAttributes attributes_from_python(const py::handle& object, std::int64_t num_vertices, std::int64_t num_faces,
                                      const char* name) {
  MeshAttributes attributes;
  if (object.is_none()) return attributes;
  const std::string top = name;
  const py::dict d =
      checked_dict(object, top, {"vertex", "corner", "face", "materials", "groups", "objects", "material_libraries"});
  const auto channels = [&](const char* key) {
    std::vector<py::handle> items = sequence_items(d, key, key_of(top, key));
    return items;
  };
  std::size_t i = 0;
  for (const py::handle item : channels("vertex"))
    attributes.vertex.push_back(channel_from_python(item, item_of(key_of(top, "vertex"), i++), false));
  i = 0;
  for (const py::handle item : channels("corner"))
    attributes.corner.push_back(corner_from_python(item, item_of(key_of(top, "corner"), i++), num_faces));
  i = 0;
  for (const py::handle item : channels("face"))
    attributes.face.push_back(channel_from_python(item, item_of(key_of(top, "face"), i++), false));
  const auto names = [&](const char* key) {
    if (!d.contains(key)) return std::vector<std::string>();
    return string_lines(d[key], key_of(top, key).c_str());
  };
  attributes.materials = names("materials");
  attributes.groups = names("groups");
  attributes.objects = names("objects");
  attributes.material_libraries = names("material_libraries");
  try {
    attributes.validate(num_vertices, num_faces);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  return attributes;
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
    } catch (const InsufficientMemoryError& e) {
      // A run that would not fit (memory.h): MemoryError, its one line unchanged.
      PyErr_SetString(PyExc_MemoryError, e.what());
    }
  });
}

}  // namespace vertexflow::python
