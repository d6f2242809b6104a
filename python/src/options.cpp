// The option table on the Python side (options.h).
#include "options.h"

#include "vertexflow/enhance_options.h"

#include <cmath>
#include <limits>
#include <optional>

namespace vertexflow::python {
namespace {

constexpr EnhanceMode kModes[] = {EnhanceMode::Flow, EnhanceMode::ReferenceFit, EnhanceMode::ReferenceFlow,
                                  EnhanceMode::Smooth, EnhanceMode::Unsharp};

const char* kind_name(OptionKind kind) {
  switch (kind) {
    case OptionKind::Bool:
      return "bool";
    case OptionKind::Int:
      return "int";
    case OptionKind::Double:
      return "float";
    case OptionKind::Choice:
      return "choice";
    case OptionKind::Indices:
      return "indices";
    case OptionKind::OptionalInt:
      return "optional_int";
  }
  return "?";
}

py::object python_value(const OptionValue& value) {
  return std::visit(
      [](const auto& v) -> py::object {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::monostate>) {
          return py::none();
        } else if constexpr (std::is_same_v<T, std::vector<Index>>) {
          if (v.empty()) return py::none();  // no pins: the keyword's default None
          py::list list;
          for (const Index i : v) list.append(i);
          return list;
        } else {
          return py::cast(v);
        }
      },
      value);
}

// Vertex indices from a 1-D integer array (or a float array of integers, or a list); None gives
// none.
std::vector<Index> indices_from(const EnhanceOptionSpec& spec, const py::handle& value) {
  if (value.is_none()) return {};
  const std::string name(spec.name);
  const py::array a = as_numeric_array(value, name.c_str());
  if (a.ndim() != 1) throw py::value_error(name + ": must be a 1-D array of vertex indices");
  if (a.dtype().kind() == 'f') {
    const DoubleArray d = DoubleArray::ensure(a);
    for (py::ssize_t i = 0; i < d.size(); ++i)
      if (d.data()[i] != std::floor(d.data()[i]))
        throw py::value_error(name + ": must hold vertex indices (integers), got " + std::to_string(d.data()[i]));
  }
  const Int64Array indices = Int64Array::ensure(a);
  if (!indices) throw py::error_already_set();
  std::vector<Index> out;
  out.reserve(static_cast<std::size_t>(indices.size()));
  for (py::ssize_t i = 0; i < indices.size(); ++i) {
    const std::int64_t index = indices.data()[i];
    if (index < 0 || index > std::numeric_limits<Index>::max())
      throw py::value_error(name + ": " + std::to_string(index) + " is not a vertex index");
    out.push_back(static_cast<Index>(index));
  }
  return out;
}

// `value` as the option's kind, or nothing when it has another type.
std::optional<OptionValue> option_value(const EnhanceOptionSpec& spec, const py::handle& value) {
  PyObject* o = value.ptr();
  switch (spec.kind) {
    case OptionKind::Bool: {
      py::detail::make_caster<bool> caster;  // True, False and numpy.bool_, nothing converted
      if (caster.load(value, false)) return OptionValue(py::detail::cast_op<bool>(caster));
      return std::nullopt;
    }
    case OptionKind::OptionalInt:
      if (value.is_none()) return OptionValue();
      [[fallthrough]];
    case OptionKind::Int: {
      if (PyBool_Check(o) || !PyIndex_Check(o)) return std::nullopt;
      const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(o));
      if (!index) throw py::error_already_set();
      int overflow = 0;
      const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
      if (overflow != 0)
        throw py::value_error(std::string(spec.name) + ": " + std::string(py::repr(value)) + " is out of range");
      return OptionValue(v);
    }
    case OptionKind::Double: {
      if (PyBool_Check(o) || py::isinstance<py::str>(value) || !PyNumber_Check(o)) return std::nullopt;
      const double v = PyFloat_AsDouble(o);
      if (v == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        return std::nullopt;
      }
      return OptionValue(v);
    }
    case OptionKind::Choice:
      if (!py::isinstance<py::str>(value)) return std::nullopt;
      return OptionValue(value.cast<std::string>());
    case OptionKind::Indices:
      return OptionValue(indices_from(spec, value));
  }
  return std::nullopt;
}

}  // namespace

py::tuple enhance_mode_names() {
  py::list names;
  for (const EnhanceMode mode : kModes) names.append(enhance_mode_name(mode));
  return py::tuple(names);
}

py::tuple enhance_option_table() {
  const EnhanceOptions defaults;
  py::list table;
  for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
    py::list choices, modes;
    for (const std::string_view choice : spec.choices) choices.append(py::str(choice.data(), choice.size()));
    for (const EnhanceMode mode : kModes)
      if (spec.modes & mode_bit(mode)) modes.append(enhance_mode_name(mode));
    const auto text = [](std::string_view s) { return py::str(s.data(), s.size()); };
    py::dict entry;
    entry["name"] = text(spec.name);
    entry["cpp"] = text(spec.cpp);
    entry["flag"] = spec.flag.empty() ? py::object(py::none()) : py::object(text(spec.flag));
    entry["flag_negates"] = spec.flag_negates;
    entry["kind"] = kind_name(spec.kind);
    entry["default"] = python_value(spec.get(defaults));
    entry["choices"] = py::tuple(choices);
    entry["min"] = spec.min;
    entry["max"] = spec.max;
    entry["min_open"] = spec.min_open;
    entry["max_open"] = spec.max_open;
    entry["help"] = text(spec.help);
    entry["modes"] = py::tuple(modes);
    table.append(entry);
  }
  return py::tuple(table);
}

EnhanceOptions enhance_options_from(const py::dict& given, const char* function, OptionNaming naming) {
  EnhanceOptions options;
  for (const auto& [key, value] : given) {
    const std::string name = py::str(key);
    const EnhanceOptionSpec* spec = find_enhance_option(name);
    if (spec == nullptr)
      throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + name + "'");
    const std::optional<OptionValue> v = option_value(*spec, value);
    if (!v) {
      // check_option_value words what the kind needs; a value of none of the kind's types makes
      // it say so, in the table's words.
      const bool no_string = spec->kind == OptionKind::Choice || spec->kind == OptionKind::Indices;
      try {
        check_option_value(*spec, no_string ? OptionValue() : OptionValue(std::string()), naming);
      } catch (const std::invalid_argument& e) {
        throw py::value_error(std::string(e.what()) + ", got " + std::string(py::repr(value)));
      }
      throw py::value_error(name + ": cannot use " + std::string(py::repr(value)));
    }
    check_option_value(*spec, *v, naming);
    spec->set(options, *v);
  }
  return options;
}

}  // namespace vertexflow::python
