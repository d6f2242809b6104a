// The Python module `vertexflow`: the library on numpy arrays, libigl-style (V: (n, 3) float64,
// F: (m, 3) integer), and the batch engine of `vertexflow batch` (apps/command_batch_core.h).
//
// Conventions (the stub vertexflow.pyi and the docstrings repeat them for Python users)
// - Input arrays go through as_vertices / as_faces: V is converted to C-contiguous float64 only
//   when it is not already (numpy returns the same object then: no copy), F to integers in
//   range. Bad arrays raise ValueError naming the argument and the problem.
// - Library errors keep their C++ message: IoError -> OSError, std::invalid_argument ->
//   ValueError, other std::exception -> RuntimeError.
// - Every heavy call releases the GIL while the library works, and takes `threads`: 0 (the
//   default) uses every core, n > 0 runs the call in a TBB task_arena of n threads (results do
//   not depend on it).
// - Nothing is printed: progress goes to the optional `progress` callable.
#include "command_batch_core.h"

#include "vertexflow/compare.h"
#include "vertexflow/curvature.h"
#include "vertexflow/fit.h"
#include "vertexflow/flow.h"
#include "vertexflow/io.h"
#include "vertexflow/line_drawing.h"
#include "vertexflow/lines.h"
#include "vertexflow/provenance.h"
#include "vertexflow/remesh.h"
#include "vertexflow/render.h"
#include "vertexflow/report_json.h"
#include "vertexflow/simplify.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/task_arena.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <utility>

namespace py = pybind11;
using namespace vertexflow;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Int64Array = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

// ---------------------------------------------------------------------------------------------
// numpy <-> Eigen

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

// V as a C-contiguous float64 (n, 3) array with n > 0 and finite values: the same object when it
// is one already.
DoubleArray as_vertices(const py::handle& object, const char* name = "V") {
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

// F as an int64 (m, 3) array with m > 0 and every index in [0, num_vertices): the same object
// when it is C-contiguous int64 already; float arrays must hold integers.
Int64Array as_faces(const py::handle& object, py::ssize_t num_vertices, const char* name = "F") {
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

struct MeshArgs {
  Vertices V;
  Faces F;
};

MeshArgs mesh_args(const py::handle& V, const py::handle& F, const char* v_name = "V", const char* f_name = "F") {
  const DoubleArray v = as_vertices(V, v_name);
  const Int64Array f = as_faces(F, v.shape(0), f_name);
  return {to_vertices(v), to_faces(f)};
}

// A numpy array that owns `matrix` (moved to the heap, freed with the array): no copy.
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

py::tuple mesh_tuple(Mesh&& mesh) {
  return py::make_tuple(to_numpy(std::move(mesh.V)), to_numpy(std::move(mesh.F)));
}

// ---------------------------------------------------------------------------------------------
// JSON -> Python

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

// ---------------------------------------------------------------------------------------------
// Threads and the GIL

void check_threads(int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores), got " + std::to_string(threads));
}

// Runs `work` without the GIL, in a task_arena of `threads` TBB threads (0: all cores).
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

// ---------------------------------------------------------------------------------------------
// Options from keywords

template <typename T>
T cast_option(const std::string& key, const py::handle& value) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::value_error("option " + key + ": cannot use " + std::string(py::repr(value)));
  }
}

template <typename Enum>
Enum enum_option(const std::string& key, const py::handle& value, const std::map<std::string, Enum>& names) {
  const auto name = cast_option<std::string>(key, value);
  const auto it = names.find(name);
  if (it != names.end()) return it->second;
  std::string allowed;
  for (const auto& [n, e] : names) allowed += (allowed.empty() ? "" : ", ") + n;
  throw py::value_error("option " + key + ": '" + name + "' is not one of " + allowed);
}

// The keywords of enhance/batch/enhance_file that fill FlowOptions (every field), by name.
using FlowSetter = std::function<void(FlowOptions&, const std::string&, const py::handle&)>;
const std::map<std::string, FlowSetter>& flow_setters() {
  static const std::map<std::string, FlowSetter> setters = {
      {"lam",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.weights.lambda = cast_option<double>(k, v); }},
      {"mu",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.weights.mu = cast_option<double>(k, v); }},
      {"epsilon", [](FlowOptions& o, const std::string& k,
                     const py::handle& v) { o.weights.epsilon = cast_option<double>(k, v); }},
      {"sliver",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.weights.sliver = cast_option<double>(k, v); }},
      {"fairness_target",
       [](FlowOptions& o, const std::string& k, const py::handle& v) {
         o.weights.fairness_target = enum_option<FairnessTarget>(
             k, v, {{"input-normal", FairnessTarget::InputNormal}, {"zero", FairnessTarget::Zero}});
       }},
      {"d_percentile",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.d_percentile = cast_option<double>(k, v); }},
      {"iterations",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.iterations = cast_option<int>(k, v); }},
      {"project_to_input",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.project_to_input = cast_option<bool>(k, v); }},
      {"feature_angle",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.feature_angle = cast_option<double>(k, v); }},
      {"fix_boundary",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.fix_boundary = cast_option<bool>(k, v); }},
      {"pins",
       [](FlowOptions& o, const std::string& k, const py::handle& v) {
         if (v.is_none()) {
           o.pinned.clear();
           return;
         }
         const Int64Array pins = Int64Array::ensure(as_numeric_array(v, "pins"));
         if (!pins || pins.ndim() != 1)
           throw py::value_error("option " + k + ": must be a 1-D array of vertex indices");
         o.pinned.assign(pins.data(), pins.data() + pins.size());
       }},
      {"refuse_non_manifold", [](FlowOptions& o, const std::string& k,
                                 const py::handle& v) { o.refuse_non_manifold = cast_option<bool>(k, v); }},
      {"max_halvings",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.max_halvings = cast_option<int>(k, v); }},
      {"min_quality",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.min_quality = cast_option<double>(k, v); }},
      {"sliver_floor",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.sliver_floor = cast_option<double>(k, v); }},
      {"curvature_smoothing_rounds",
       [](FlowOptions& o, const std::string& k, const py::handle& v) {
         o.curvature.smoothing_rounds = cast_option<int>(k, v);
       }},
      {"normal_weighting",
       [](FlowOptions& o, const std::string& k, const py::handle& v) {
         o.curvature.normal_weighting = enum_option<NormalWeighting>(k, v,
                                                                     {{"max1999", NormalWeighting::Max1999},
                                                                      {"area", NormalWeighting::Area},
                                                                      {"angle", NormalWeighting::Angle}});
       }},
      {"solver",
       [](FlowOptions& o, const std::string& k, const py::handle& v) {
         o.solver = enum_option<LinearSolver>(k, v,
                                              {{"automatic", LinearSolver::Automatic},
                                               {"direct", LinearSolver::Direct},
                                               {"iterative", LinearSolver::Iterative},
                                               {"multilevel", LinearSolver::Multilevel}});
       }},
      {"solver_tolerance", [](FlowOptions& o, const std::string& k,
                              const py::handle& v) { o.solver_tolerance = cast_option<double>(k, v); }},
      {"density_passes",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.density.passes = cast_option<int>(k, v); }},
      {"density_exponent", [](FlowOptions& o, const std::string& k,
                              const py::handle& v) { o.density.exponent = cast_option<double>(k, v); }},
      {"density_epsilon", [](FlowOptions& o, const std::string& k,
                             const py::handle& v) { o.density.epsilon = cast_option<double>(k, v); }},
      {"density_step",
       [](FlowOptions& o, const std::string& k, const py::handle& v) { o.density.step = cast_option<double>(k, v); }},
  };
  return setters;
}

// Fills `options` from the keywords named in flow_setters(); returns the others.
py::dict take_flow_options(const py::kwargs& kwargs, FlowOptions& options) {
  py::dict rest;
  for (const auto& [key, value] : kwargs) {
    const auto name = key.cast<std::string>();
    const auto it = flow_setters().find(name);
    if (it != flow_setters().end())
      it->second(options, name, value);
    else
      rest[key] = value;
  }
  return rest;
}

[[noreturn]] void unknown_keyword(const char* function, const py::dict& rest) {
  std::string names;
  for (const auto& [key, value] : rest) names += (names.empty() ? "" : ", ") + key.cast<std::string>();
  throw py::type_error(std::string(function) + "() got unexpected keyword argument(s): " + names);
}

// Pops `name` from `rest`, or returns `fallback`.
template <typename T>
T pop_option(py::dict& rest, const char* name, T fallback) {
  if (!rest.contains(name)) return fallback;
  py::object value = rest[name];
  PyDict_DelItemString(rest.ptr(), name);
  if constexpr (std::is_same_v<T, py::object>) {
    return value;
  } else {
    return cast_option<T>(name, value);
  }
}

void report_progress(const py::object& progress, const std::string& message) {
  if (!progress.is_none()) progress(message);
}

// ---------------------------------------------------------------------------------------------
// The functions

py::tuple py_read_mesh(const std::filesystem::path& path, bool comments) {
  Mesh mesh;
  {
    py::gil_scoped_release release;
    mesh = read_mesh(path);
  }
  if (!comments) return mesh_tuple(std::move(mesh));
  py::list lines;
  for (const std::string& line : mesh.comments) lines.append(line);
  const py::tuple pair = mesh_tuple(std::move(mesh));
  return py::make_tuple(pair[0], pair[1], lines);
}

// A sequence of str (not a str itself, which would read as one line per character).
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

void py_write_mesh(const std::filesystem::path& path, const py::handle& V, const py::handle& F, bool ascii,
                   const py::object& comments) {
  MeshArgs args = mesh_args(V, F);
  Mesh mesh;
  mesh.V = std::move(args.V);
  mesh.F = std::move(args.F);
  mesh.comments = string_lines(comments, "comments");
  WriteOptions options;
  if (ascii) {
    options.ply_encoding = PlyEncoding::Ascii;
    options.stl_binary = false;
  }
  py::gil_scoped_release release;
  write_mesh(path, mesh, options);
}

py::object py_principal_curvatures(const py::handle& V, const py::handle& F, int smoothing_rounds, int threads) {
  const MeshArgs args = mesh_args(V, F);
  CurvatureOptions options;
  if (smoothing_rounds < 0) throw py::value_error("smoothing_rounds must be >= 0");
  options.smoothing_rounds = smoothing_rounds;
  Curvature c = without_gil(threads, [&] { return principal_curvatures(args.V, args.F, options); });
  static py::handle type = [] {
    py::object t = py::module_::import("vertexflow").attr("PrincipalCurvatures");
    return t.release();
  }();
  return type(to_numpy(std::move(c.k1)), to_numpy(std::move(c.k2)), to_numpy(std::move(c.T1)),
              to_numpy(std::move(c.T2)), to_numpy(std::move(c.N)));
}

py::tuple py_enhance(const py::handle& V, const py::handle& F, const py::kwargs& kwargs) {
  FlowOptions flow;
  py::dict rest = take_flow_options(kwargs, flow);
  const auto surface = pop_option<std::string>(rest, "surface", "input");
  const py::object reference = pop_option<py::object>(rest, "reference", py::none());
  const py::object max_rounds = pop_option<py::object>(rest, "max_rounds", py::none());
  const bool assume_on_surface = pop_option<bool>(rest, "assume_on_surface", false);
  const std::vector<std::string> provenance =
      string_lines(pop_option<py::object>(rest, "provenance", py::none()), "provenance");
  const auto reference_method = pop_option<std::string>(rest, "reference_method", "fit");
  const int threads = pop_option<int>(rest, "threads", 0);
  const py::object progress = pop_option<py::object>(rest, "progress", py::none());
  if (rest.size() > 0) unknown_keyword("enhance", rest);
  if (surface != "input" && surface != "smooth")
    throw py::value_error("option surface: '" + surface + "' is not one of input, smooth");
  if (reference_method != "fit" && reference_method != "flow")
    throw py::value_error("option reference_method: '" + reference_method + "' is not one of fit, flow");
  const bool on_reference = !reference.is_none();
  const bool reference_flow = on_reference && reference_method == "flow";
  const bool fit = on_reference && !reference_flow;
  if (on_reference && surface == "smooth") throw py::value_error("reference and surface='smooth' exclude each other");
  if (reference_flow && !max_rounds.is_none())
    throw py::value_error("max_rounds does not apply to reference_method='flow'");
  if (assume_on_surface && surface != "smooth")
    throw py::value_error("assume_on_surface applies to surface='smooth' only");

  const MeshArgs args = mesh_args(V, F);
  validate_flow_options(flow, static_cast<Index>(args.V.rows()));
  MeshArgs ref;
  if (on_reference) {
    if (!py::isinstance<py::tuple>(reference) && !py::isinstance<py::list>(reference))
      throw py::value_error("reference must be a pair (V, F) of the dense mesh");
    const py::sequence pair = reference.cast<py::sequence>();
    if (pair.size() != 2) throw py::value_error("reference must be a pair (V, F) of the dense mesh");
    ref = mesh_args(pair[0], pair[1], "reference V", "reference F");
  }
  // As `vertexflow enhance` maps its options to the fitting modes.
  FitOptions fit_options;
  fit_options.fix_boundary = flow.fix_boundary;
  fit_options.pinned = flow.pinned;
  fit_options.min_quality = flow.min_quality;
  fit_options.sliver_floor = flow.sliver_floor;
  SmoothFitOptions smooth;
  smooth.surface.feature_angle = flow.feature_angle;
  smooth.fit.fix_boundary = fit_options.fix_boundary;
  smooth.fit.pinned = fit_options.pinned;
  smooth.fit.min_quality = fit_options.min_quality;
  smooth.fit.sliver_floor = fit_options.sliver_floor;
  if (!max_rounds.is_none()) {  // otherwise each mode's own default (10 for the fit, 1 for smooth)
    fit_options.max_rounds = cast_option<int>("max_rounds", max_rounds);
    smooth.fit.max_rounds = fit_options.max_rounds;
  }
  if (assume_on_surface) smooth.max_poor_face_fraction = 1.0;
  // As the CLI: an input whose provenance records a fit is held (provenance.h).
  const std::string* fitted_by = find_fit_provenance(provenance);
  smooth.already_fitted = fitted_by != nullptr && !assume_on_surface;

  const std::string method = fit                   ? "reference"
                             : reference_flow      ? "reference-flow"
                             : surface == "smooth" ? "smooth"
                                                   : "flow";
  report_progress(progress, "enhance: " + method + " on " + std::to_string(args.V.rows()) + " vertices");
  Vertices out;
  nlohmann::json report;
  without_gil(threads, [&] {
    if (fit) {
      FitResult r = fit_to_reference(args.V, args.F, ref.V, ref.F, fit_options);
      report = r.report;
      report["options"] = fit_options;
      out = std::move(r.V);
    } else if (surface == "smooth") {
      FitResult r = fit_to_smooth_surface(args.V, args.F, smooth);
      report = r.report;
      report["options"] = smooth.fit;
      report["options"]["surface"] = smooth.surface;
      report["options"]["max_poor_face_fraction"] = smooth.max_poor_face_fraction;
      report["fit"]["poor_face_fraction"] = r.report.poor_face_fraction;
      report["fit"]["held_as_decimated"] = r.report.held_as_decimated;
      report["fit"]["held_as_fitted"] = r.report.held_as_fitted;
      report["fit"]["fitted_by"] = r.report.held_as_fitted ? nlohmann::json(*fitted_by) : nlohmann::json();
      out = std::move(r.V);
    } else {
      FlowResult r = reference_flow ? vertex_flow_on_reference(args.V, args.F, ref.V, ref.F, flow)
                                    : vertex_flow(args.V, args.F, flow);
      report = r.report;
      report["options"] = flow;
      report["held_non_manifold_vertices"] = r.report.held_non_manifold_vertices;
      report["reoriented_faces"] = r.report.reoriented_faces;
      report["cut_edges"] = r.report.cut_edges;
      out = std::move(r.V);
    }
  });
  report["method"] = method;
  ProvenanceRun run;
  run.mode = fit                   ? EnhanceMode::ReferenceFit
             : reference_flow      ? EnhanceMode::ReferenceFlow
             : surface == "smooth" ? EnhanceMode::Smooth
                                   : EnhanceMode::Flow;
  run.assume_on_surface = assume_on_surface;
  if (surface == "smooth" && report["fit"]["held_as_fitted"].get<bool>()) run.held = "already fitted";
  if (surface == "smooth" && report["fit"]["held_as_decimated"].get<bool>()) run.held = "decimated";
  report["provenance"] = provenance_line(run);
  report_progress(progress, "enhance: done");
  return py::make_tuple(to_numpy(std::move(out)), to_python(report));
}

nlohmann::json distance_json(const SymmetricDistance& d) {
  const auto one = [](const DistanceStats& s) {
    return nlohmann::json{{"mean", s.mean}, {"rms", s.rms}, {"max", s.max}, {"points", s.points}};
  };
  return {{"mean", d.mean()},
          {"rms", d.rms()},
          {"hausdorff", d.hausdorff},
          {"a_to_b", one(d.a_to_b)},
          {"b_to_a", one(d.b_to_a)}};
}

py::dict py_compare(const py::handle& V_result, const py::handle& F_result, const py::handle& V_input,
                    const py::handle& F_input, const py::object& reference, int threads) {
  Mesh result, input, ref;
  {
    MeshArgs a = mesh_args(V_result, F_result, "V_result", "F_result");
    result.V = std::move(a.V);
    result.F = std::move(a.F);
    MeshArgs b = mesh_args(V_input, F_input, "V_input", "F_input");
    input.V = std::move(b.V);
    input.F = std::move(b.F);
  }
  const bool has_reference = !reference.is_none();
  if (has_reference) {
    const py::sequence pair = reference.cast<py::sequence>();
    if (pair.size() != 2) throw py::value_error("reference must be a pair (V, F)");
    MeshArgs c = mesh_args(pair[0], pair[1], "reference V", "reference F");
    ref.V = std::move(c.V);
    ref.F = std::move(c.F);
  }
  const MeshComparison c =
      without_gil(threads, [&] { return compare_meshes(result, input, has_reference ? &ref : nullptr); });
  nlohmann::json j;
  const auto edge = [](const EdgeErrorStats& s) {
    return nlohmann::json{
        {"mean", s.mean}, {"max_over_mean", s.max_over_mean}, {"coefficient_of_variation", s.coefficient_of_variation}};
  };
  const auto quality = [](const QualityStats& q) {
    return nlohmann::json{{"min", q.min}, {"mean", q.mean}, {"p5", q.p5}, {"fraction_below_0_3", q.fraction_below_0_3}};
  };
  const auto percentiles = [](const MeanCurvaturePercentiles& h) {
    return nlohmann::json{{"p5", h.p5}, {"p50", h.p50}, {"p95", h.p95}, {"p99", h.p99}};
  };
  j["length_scale"] = c.length_scale;
  j["has_reference"] = c.has_reference;
  j["distance"]["result_input"] = distance_json(c.result_input);
  j["distance"]["result_reference"] = c.result_reference ? distance_json(*c.result_reference) : nlohmann::json(nullptr);
  j["distance"]["input_reference"] = c.input_reference ? distance_json(*c.input_reference) : nlohmann::json(nullptr);
  j["edge_error"] = {{"input", edge(c.edge_error_input)}, {"result", edge(c.edge_error_result)}};
  j["redistribution_rho"] = {{"input", c.redistribution_rho_input}, {"result", c.redistribution_rho_result}};
  j["abs_mean_curvature"] = {{"input", percentiles(c.abs_mean_curvature_input)},
                             {"result", percentiles(c.abs_mean_curvature_result)}};
  j["quality"] = {{"input", quality(c.quality_input)}, {"result", quality(c.quality_result)}};
  j["degenerate_faces"] = {{"input", c.degenerate_faces_input}, {"result", c.degenerate_faces_result}};
  j["same_connectivity"] = c.same_connectivity;
  j["flipped_faces"] = c.flipped_faces ? nlohmann::json(*c.flipped_faces) : nlohmann::json(nullptr);
  return to_python(j);
}

py::tuple py_simplify(const py::handle& V, const py::handle& F, Index faces, double ratio, bool keep_boundary,
                      int threads) {
  const MeshArgs args = mesh_args(V, F);
  SimplifyOptions options;
  options.target_faces = faces;
  options.target_ratio = ratio;
  options.keep_boundary = keep_boundary;
  if (faces < 0) throw py::value_error("faces must be >= 0 (0: use ratio)");
  SimplifyResult r = without_gil(threads, [&] { return simplify(args.V, args.F, options); });
  return mesh_tuple(std::move(r.mesh));
}

py::tuple py_remesh(const py::handle& V, const py::handle& F, Index target_vertices, double tolerance, int max_attempts,
                    int iterations, int threads) {
  const MeshArgs args = mesh_args(V, F);
  RemeshOptions options;
  options.target_vertices = target_vertices;
  options.tolerance = tolerance;
  options.max_attempts = max_attempts;
  options.isotropic.iterations = iterations;
  RemeshResult r = without_gil(threads, [&] { return remesh_to_vertex_count(args.V, args.F, options); });
  return mesh_tuple(std::move(r.mesh));
}

py::array py_render(const py::handle& V, const py::handle& F, int width, int height, const std::string& view,
                    const std::string& color, const std::string& shading, bool wireframe, double azimuth,
                    double elevation, const py::object& displacement_reference, bool color_bar, int samples,
                    int threads) {
  MeshArgs args = mesh_args(V, F);
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.view = enum_option<RenderView>("view", py::str(view),
                                         {{"front", RenderView::Front},
                                          {"side", RenderView::Side},
                                          {"top", RenderView::Top},
                                          {"iso", RenderView::Iso},
                                          {"custom", RenderView::Custom}});
  options.color = enum_option<RenderColor>("color", py::str(color),
                                           {{"none", RenderColor::None},
                                            {"mean", RenderColor::Mean},
                                            {"gauss", RenderColor::Gauss},
                                            {"quality", RenderColor::Quality},
                                            {"displacement", RenderColor::Displacement}});
  options.shading = enum_option<RenderShading>(
      "shading", py::str(shading),
      {{"smooth", RenderShading::Smooth}, {"flat", RenderShading::Flat}, {"exaggerated", RenderShading::Exaggerated}});
  options.wireframe = wireframe;
  options.azimuth_degrees = azimuth;
  options.elevation_degrees = elevation;
  options.color_bar = color_bar;
  options.samples = samples;
  if (!displacement_reference.is_none())
    options.displacement_reference = to_vertices(as_vertices(displacement_reference, "displacement_reference"));
  Mesh mesh;
  mesh.V = std::move(args.V);
  mesh.F = std::move(args.F);
  // threads limits the TBB part (arrays, colours); llvmpipe rasterises with LP_NUM_THREADS.
  const Image image = without_gil(threads, [&] { return render_mesh(mesh, options); });
  py::array_t<std::uint8_t> rgb(
      {static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), static_cast<py::ssize_t>(3)});
  std::uint8_t* out = rgb.mutable_data();
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  for (std::size_t i = 0; i < pixels; ++i) std::memcpy(out + 3 * i, image.pixels.data() + 4 * i, 3);
  return rgb;
}

// Line options from keyword values (lines.h); the same names as the CLI's, with underscores.
LineOptions line_options(bool contours, bool suggestive_contours, bool ridges, bool valleys,
                         double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                         double length_scale) {
  LineOptions o;
  o.contours = contours;
  o.suggestive_contours = suggestive_contours;
  o.ridges = ridges;
  o.valleys = valleys;
  o.suggestive_threshold = suggestive_threshold;
  o.ridge_threshold = ridge_threshold;
  o.smoothing_scale = smoothing_scale;
  o.length_scale = length_scale;
  return o;
}

py::array_t<double> points_array(const std::vector<Eigen::Vector2d>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), static_cast<py::ssize_t>(2)});
  double* data = out.mutable_data();
  for (std::size_t i = 0; i < points.size(); ++i) data[2 * i] = points[i].x(), data[2 * i + 1] = points[i].y();
  return out;
}

py::list py_feature_lines(const py::handle& V, const py::handle& F, const py::object& direction, const py::object& eye,
                          bool contours, bool suggestive_contours, bool ridges, bool valleys,
                          double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                          double length_scale, int threads) {
  MeshArgs args = mesh_args(V, F);
  if (!direction.is_none() && !eye.is_none())
    throw std::invalid_argument("feature_lines: give direction (orthographic) or eye (perspective), not both");
  View view;
  view.orthographic = eye.is_none();
  const auto vec3 = [](const py::object& o, const char* name) {
    const std::vector<double> v = o.cast<std::vector<double>>();
    if (v.size() != 3) throw std::invalid_argument(std::string("feature_lines: ") + name + " needs 3 values");
    return Eigen::Vector3d(v[0], v[1], v[2]);
  };
  if (!direction.is_none()) view.direction = vec3(direction, "direction");
  if (!eye.is_none()) view.eye = vec3(eye, "eye");
  const LineOptions options = line_options(contours, suggestive_contours, ridges, valleys, suggestive_threshold,
                                           ridge_threshold, smoothing_scale, length_scale);
  const std::vector<Polyline> lines =
      without_gil(threads, [&] { return feature_lines(args.V, args.F, view, options); });
  py::list out;
  for (const Polyline& line : lines) {
    py::array_t<double> points({static_cast<py::ssize_t>(line.points.rows()), static_cast<py::ssize_t>(3)});
    std::memcpy(points.mutable_data(), line.points.data(), sizeof(double) * 3 * line.points.rows());
    out.append(py::dict(py::arg("type") = std::string(line_type_name(line.type)), py::arg("points") = points,
                        py::arg("closed") = line.closed));
  }
  return out;
}

LineDrawingOptions drawing_options(int width, int height, const std::string& view, double azimuth, double elevation,
                                   const LineOptions& lines, bool hidden_line_removal) {
  LineDrawingOptions o;
  o.render.width = width;
  o.render.height = height;
  o.render.view = enum_option<RenderView>("view", py::str(view),
                                          {{"front", RenderView::Front},
                                           {"side", RenderView::Side},
                                           {"top", RenderView::Top},
                                           {"iso", RenderView::Iso},
                                           {"custom", RenderView::Custom}});
  o.render.azimuth_degrees = azimuth;
  o.render.elevation_degrees = elevation;
  o.lines = lines;
  o.hidden_line_removal = hidden_line_removal;
  return o;
}

py::dict py_line_drawing(const py::handle& V, const py::handle& F, int width, int height, const std::string& view,
                         double azimuth, double elevation, bool contours, bool suggestive_contours, bool ridges,
                         bool valleys, double suggestive_threshold, double ridge_threshold, double smoothing_scale,
                         double length_scale, bool hidden_line_removal, double line_width, int threads) {
  MeshArgs args = mesh_args(V, F);
  Mesh mesh;
  mesh.V = std::move(args.V);
  mesh.F = std::move(args.F);
  const LineDrawingOptions options =
      drawing_options(width, height, view, azimuth, elevation,
                      line_options(contours, suggestive_contours, ridges, valleys, suggestive_threshold,
                                   ridge_threshold, smoothing_scale, length_scale),
                      hidden_line_removal);
  const LineDrawing drawing = without_gil(threads, [&] { return draw_lines(mesh, options); });
  py::list lines;
  for (const ImagePolyline& line : drawing.lines)
    lines.append(py::dict(py::arg("type") = std::string(line_type_name(line.type)),
                          py::arg("points") = points_array(line.points)));
  return py::dict(py::arg("lines") = lines, py::arg("svg") = svg_document(drawing, line_width),
                  py::arg("width") = drawing.width, py::arg("height") = drawing.height);
}

py::dict py_compare_lines(const py::handle& Vc, const py::handle& Fc, const py::handle& Vd, const py::handle& Fd,
                          int views, double elevation, int width, int height, double match_pixels, int threads) {
  MeshArgs coarse_args = mesh_args(Vc, Fc, "V_coarse", "F_coarse"),
           dense_args = mesh_args(Vd, Fd, "V_dense", "F_dense");
  Mesh coarse, dense;
  coarse.V = std::move(coarse_args.V), coarse.F = std::move(coarse_args.F);
  dense.V = std::move(dense_args.V), dense.F = std::move(dense_args.F);
  LineFidelityOptions options;
  options.views = views;
  options.elevation_degrees = elevation;
  options.width = width;
  options.height = height;
  options.match_pixels = match_pixels;
  const LineFidelity fidelity = without_gil(threads, [&] { return line_drawing_fidelity(coarse, dense, options); });
  py::list per_view;
  for (const LineFidelityView& v : fidelity.views)
    per_view.append(py::dict(py::arg("azimuth") = v.azimuth_degrees, py::arg("precision") = v.precision,
                             py::arg("recall") = v.recall, py::arg("f1") = v.f1,
                             py::arg("coarse_pixels") = v.coarse_pixels, py::arg("dense_pixels") = v.dense_pixels));
  return py::dict(py::arg("precision") = fidelity.precision, py::arg("recall") = fidelity.recall,
                  py::arg("f1") = fidelity.f1, py::arg("views") = per_view);
}

cli::BatchFileOptions batch_file_options(py::dict& rest, const py::kwargs& kwargs) {
  cli::BatchFileOptions options;
  rest = take_flow_options(kwargs, options.flow);
  options.force = pop_option<bool>(rest, "force", false);
  options.metrics = pop_option<bool>(rest, "metrics", true);
  options.threads = pop_option<int>(rest, "threads", 0);
  check_threads(options.threads);
  validate_flow_options(options.flow);
  return options;
}

py::dict py_enhance_file(const std::filesystem::path& input, const std::filesystem::path& output,
                         const py::kwargs& kwargs) {
  py::dict rest;
  const cli::BatchFileOptions options = batch_file_options(rest, kwargs);
  if (rest.size() > 0) unknown_keyword("enhance_file", rest);
  cli::BatchRow row;
  {
    py::gil_scoped_release release;
    row = cli::enhance_file(input, output, options);
  }
  return to_python(cli::to_json(row));
}

py::dict py_batch(const py::object& inputs, const std::filesystem::path& output_dir, const py::kwargs& kwargs) {
  cli::BatchOptions options;
  py::dict rest;
  options.file = batch_file_options(rest, kwargs);
  options.jobs = pop_option<int>(rest, "jobs", 1);
  const py::object progress = pop_option<py::object>(rest, "progress", py::none());
  if (rest.size() > 0) unknown_keyword("batch", rest);
  if (py::isinstance<py::str>(inputs) || py::hasattr(inputs, "__fspath__")) {
    options.inputs = {py::str(py::module_::import("os").attr("fspath")(inputs)).cast<std::string>()};
  } else {
    for (const auto& item : inputs)
      options.inputs.push_back(py::str(py::module_::import("os").attr("fspath")(item)).cast<std::string>());
  }
  options.output_dir = output_dir;
  if (!progress.is_none()) {
    options.progress = [progress](const cli::BatchProgress& p) {
      py::gil_scoped_acquire acquire;
      try {
        py::dict d;
        d["finished"] = p.finished;
        d["total"] = p.total;
        d["failed"] = p.failed;
        d["input"] = p.row->input;
        d["status"] = p.row->status;
        d["error"] = p.row->error.empty() ? py::object(py::none()) : py::object(py::str(p.row->error));
        d["elapsed"] = p.elapsed;
        d["eta"] = p.eta >= 0 ? py::object(py::float_(p.eta)) : py::object(py::none());
        progress(d);
      } catch (py::error_already_set& e) {
        // An exception in the callback must not stop the batch (or cross a worker thread).
        e.discard_as_unraisable("vertexflow.batch progress callback");
      }
    };
  }
  cli::BatchSummary summary;
  {
    py::gil_scoped_release release;
    summary = cli::run_batch(options);
  }
  py::dict d;
  py::list rows;
  for (const auto& row : summary.rows) rows.append(to_python(cli::to_json(row)));
  d["files"] = rows;
  d["done"] = summary.done;
  d["skipped"] = summary.skipped;
  d["failed"] = summary.failed;
  d["seconds"] = summary.seconds;
  d["csv"] = summary.csv.string();
  d["json"] = summary.json.string();
  return d;
}

// For bench/python_overhead.py: the wall-clock seconds of `repeats` vertex_flow calls made from
// C++ on matrices already converted (what a C++ program pays), without the GIL.
std::vector<double> py_time_vertex_flow(const py::handle& V, const py::handle& F, int repeats, int threads) {
  const MeshArgs args = mesh_args(V, F);
  std::vector<double> seconds;
  without_gil(threads, [&] {
    for (int i = 0; i < repeats; ++i) {
      const auto start = std::chrono::steady_clock::now();
      const FlowResult r = vertex_flow(args.V, args.F, FlowOptions{});
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  });
  return seconds;
}

}  // namespace

PYBIND11_MODULE(vertexflow, m) {
  m.doc() = R"doc(vertexflow: feature enhancement of triangle meshes by vertex flow (Ji et al. 2011).

Meshes are numpy arrays, libigl-style: V is (n, 3) float64 (other dtypes and orders are converted;
C-contiguous float64 is used as it is), F is (m, 3) integer vertex indices. Bad arrays and options
raise ValueError, file problems OSError, each with the library's message. Heavy calls release the
GIL and take threads=0 (all cores) or a thread count; results do not depend on it. Nothing is
printed: pass progress=callable to hear about progress.)doc";

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });

  m.attr("__version__") = "0.1.0";
  m.attr("PrincipalCurvatures") =
      py::module_::import("collections")
          .attr("namedtuple")("PrincipalCurvatures", py::make_tuple("k1", "k2", "T1", "T2", "N"));
  m.attr("PrincipalCurvatures").attr("__module__") = "vertexflow";
  {
    // The names of the FlowOptions keywords, for introspection (and the stub's test).
    py::list names;
    for (const auto& entry : flow_setters()) names.append(entry.first);
    m.attr("FLOW_OPTIONS") = py::tuple(names);
  }

  m.def(
      "as_vertices", [](const py::handle& V) { return as_vertices(V); }, py::arg("V"),
      R"doc(V as the module uses it: a C-contiguous float64 (n, 3) array, n > 0, finite. Returns V itself
when it is one already (no copy), else a converted copy. Raises ValueError otherwise.)doc");
  m.def(
      "as_faces", [](const py::handle& F, py::ssize_t n) { return as_faces(F, n); }, py::arg("F"),
      py::arg("num_vertices"),
      R"doc(F as the module uses it: a C-contiguous int64 (m, 3) array, m > 0, every index in
[0, num_vertices). Returns F itself when it is one already. Raises ValueError otherwise.)doc");

  m.def("read_mesh", &py_read_mesh, py::arg("path"), py::kw_only(), py::arg("comments") = false,
        R"doc(Reads a mesh (OBJ, PLY, OFF, STL, optionally .gz) into (V, F): V (n, 3) float64, F (m, 3) int32.
Polygons are triangulated and the mesh cleaned as vertexflow's reader does (io.h). comments=True
returns (V, F, comments): the file's comment lines as a list of str (PLY `comment`, OBJ and OFF
'#' lines; at most 256, each cut to 1024 bytes), which hold the provenance lines of
`vertexflow enhance` (pass them to enhance(provenance=...)). Raises OSError with "FILE: problem"
for any file problem.)doc");
  m.def("write_mesh", &py_write_mesh, py::arg("path"), py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("ascii") = false, py::arg("comments") = py::none(),
        R"doc(Writes (V, F) atomically (temporary file, then rename); the format follows the extension
(.obj, .ply, .off, .stl, optionally .gz). PLY keeps float64 coordinates exactly. ascii=True writes
ASCII PLY/STL. comments, a sequence of str, are written as comment lines (PLY, OBJ, ASCII OFF;
STL and binary OFF have none). Raises ValueError for bad arrays, OSError for file problems.)doc");
  m.def("principal_curvatures", &py_principal_curvatures, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("smoothing_rounds") = 0, py::arg("threads") = 0,
        R"doc(Principal curvatures (Rusinkiewicz 2004) of every vertex: PrincipalCurvatures(k1, k2, T1, T2, N),
k1 >= k2 (n,) arrays, T1, T2, N unit (n, 3) arrays. Convex with outward normals is positive.)doc");
  m.def("enhance", &py_enhance, py::arg("V"), py::arg("F"),
        R"doc(enhance(V, F, *, lam=1.0, mu=0.5, iterations=1, pins=None, surface="input", reference=None,
        epsilon=1e-6, sliver=0.02, fairness_target="input-normal", d_percentile=99.0,
        project_to_input=True, feature_angle=40.0, fix_boundary=True, refuse_non_manifold=False,
        max_halvings=30, min_quality=0.3, sliver_floor=0.5, curvature_smoothing_rounds=0,
        normal_weighting="max1999", solver="automatic", solver_tolerance=1e-7, density_passes=0,
        density_exponent=2.0, density_epsilon=0.1, density_step=0.5, max_rounds=None,
        reference_method="fit", assume_on_surface=False, provenance=None, threads=0,
        progress=None) -> (V_out, report)

Moves the vertices of (V, F) by vertex flow (same connectivity); every FlowOptions field is a
keyword (flow.h documents them). surface="smooth" or reference=(V_ref, F_ref) fit the vertices
instead, as `vertexflow enhance --surface smooth` / `--reference` do (max_rounds applies to them;
None keeps each mode's default: 10 rounds for the reference, 1 for smooth). reference_method="flow"
runs the paper's flow on the reference (`--reference-method flow`); assume_on_surface=True fits
smooth mode's input even when it looks decimated (`--assume-on-surface`). provenance, the input's
comment lines (read_mesh(path, comments=True)), lets smooth mode hold an input that an earlier
smooth-mode or reference-mode fit placed off its surface, as the CLI does (report["fit"]
["held_as_fitted"], ["fitted_by"]); assume_on_surface=True fits it anyway.
V_out is bit for bit what `vertexflow enhance` writes for the same options. report is the dict of
the enhance report's method sections (options, solver, guard, seconds) and "provenance", the
line the CLI would add to the output's comments. progress(str) is called before and after.)doc");
  m.def("compare", &py_compare, py::arg("V_result"), py::arg("F_result"), py::arg("V_input"), py::arg("F_input"),
        py::kw_only(), py::arg("reference") = py::none(), py::arg("threads") = 0,
        R"doc(Every figure of docs/metrics.md for a result against its input (and a dense reference=(V, F)):
distances, edge-error CV, redistribution rho, |H| percentiles, quality, degenerate and flipped faces.)doc");
  m.def("simplify", &py_simplify, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("faces") = 0,
        py::arg("ratio") = SimplifyOptions{}.target_ratio, py::arg("keep_boundary") = true, py::arg("threads") = 0,
        R"doc(QEM simplification to `faces` faces (or ratio * #F when faces is 0) -> (V, F).)doc");
  m.def("remesh", &py_remesh, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("target_vertices") = RemeshOptions{}.target_vertices, py::arg("tolerance") = RemeshOptions{}.tolerance,
        py::arg("max_attempts") = RemeshOptions{}.max_attempts,
        py::arg("iterations") = IsotropicRemeshOptions{}.iterations, py::arg("threads") = 0,
        R"doc(Isotropic remeshing (CGAL) to about target_vertices vertices -> (V, F).)doc");
  m.def("render", &py_render, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("width") = 800,
        py::arg("height") = 600, py::arg("view") = "iso", py::arg("color") = "none", py::arg("shading") = "smooth",
        py::arg("wireframe") = false, py::arg("azimuth") = 30.0, py::arg("elevation") = 20.0,
        py::arg("displacement_reference") = py::none(), py::arg("color_bar") = true, py::arg("samples") = 4,
        py::arg("threads") = 0,
        R"doc(Renders the mesh off-screen (OSMesa) -> (height, width, 3) uint8 RGB array, rows top to bottom.
view: front, side, top, iso, custom (azimuth, elevation); color: none, mean, gauss, quality,
displacement (needs displacement_reference, the positions before); shading: smooth, flat,
exaggerated (Rusinkiewicz et al. 2006, render.h's default options).
threads limits the TBB part; llvmpipe rasterises with LP_NUM_THREADS threads.)doc");
  m.def("feature_lines", &py_feature_lines, py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("direction") = py::none(), py::arg("eye") = py::none(), py::arg("contours") = true,
        py::arg("suggestive_contours") = true, py::arg("ridges") = true, py::arg("valleys") = true,
        py::arg("suggestive_threshold") = LineOptions{}.suggestive_threshold,
        py::arg("ridge_threshold") = LineOptions{}.ridge_threshold, py::arg("smoothing_scale") = 0.0,
        py::arg("length_scale") = 0.0, py::arg("threads") = 0,
        R"doc(The feature lines as 3D polylines (lines.h) -> [{"type", "points" (N, 3), "closed"}].
Orthographic along direction (default (0, 0, -1)) or perspective from eye. type is contours,
suggestive-contours, ridges or valleys; thresholds in units of L (length_scale, default the
bounding-box diagonal). Hidden lines are not removed: line_drawing does that.)doc");
  m.def("line_drawing", &py_line_drawing, py::arg("V"), py::arg("F"), py::kw_only(), py::arg("width") = 800,
        py::arg("height") = 600, py::arg("view") = "iso", py::arg("azimuth") = 30.0, py::arg("elevation") = 20.0,
        py::arg("contours") = true, py::arg("suggestive_contours") = true, py::arg("ridges") = true,
        py::arg("valleys") = true, py::arg("suggestive_threshold") = LineOptions{}.suggestive_threshold,
        py::arg("ridge_threshold") = LineOptions{}.ridge_threshold, py::arg("smoothing_scale") = 0.0,
        py::arg("length_scale") = 0.0, py::arg("hidden_line_removal") = true, py::arg("line_width") = 1.5,
        py::arg("threads") = 0,
        R"doc(`vertexflow lines` in memory (line_drawing.h) -> {"lines": [{"type", "points" (N, 2) pixels}],
"svg": str, "width", "height"}: render's camera, hidden lines removed with its depth buffer.)doc");
  m.def("compare_lines", &py_compare_lines, py::arg("V_coarse"), py::arg("F_coarse"), py::arg("V_dense"),
        py::arg("F_dense"), py::kw_only(), py::arg("views") = LineFidelityOptions{}.views,
        py::arg("elevation") = LineFidelityOptions{}.elevation_degrees, py::arg("width") = LineFidelityOptions{}.width,
        py::arg("height") = LineFidelityOptions{}.height, py::arg("match_pixels") = LineFidelityOptions{}.match_pixels,
        py::arg("threads") = 0,
        R"doc(`vertexflow compare-lines`: line-drawing fidelity of the coarse mesh against the dense one
(line_drawing.h) -> {"precision", "recall", "f1", "views": [per view]}.)doc");
  m.def("enhance_file", &py_enhance_file, py::arg("input"), py::arg("output"),
        R"doc(enhance_file(input, output, *, force=False, metrics=True, threads=0, **flow options) -> dict

One file of `vertexflow batch`: reads input, enhances it, writes output atomically (the bytes
`vertexflow enhance` writes) and measures it. Never raises for a problem of the file: the row's
status is "done", "skipped" (output exists and not force) or "failed" with its "error".)doc");
  m.def("_time_vertex_flow", &py_time_vertex_flow, py::arg("V"), py::arg("F"), py::arg("repeats") = 1,
        py::arg("threads") = 0,
        "Seconds of each of `repeats` vertex_flow calls made from C++ (bench/python_overhead.py).");
  m.def("batch", &py_batch, py::arg("inputs"), py::arg("output_dir"),
        R"doc(batch(inputs, output_dir, *, jobs=1, threads=0, force=False, metrics=True, progress=None,
      **flow options) -> dict

`vertexflow batch`: enhance_file over a directory, glob pattern or list of them, jobs files at
once (threads TBB threads each; 0: the cores divided among the jobs). Failing files are reported
and skipped; existing outputs are skipped unless force. Writes output_dir/batch_summary.csv and
.json; returns {"files": [rows], "done", "skipped", "failed", "seconds", "csv", "json"}.
progress(dict) is called after each file (finished, total, failed, input, status, error, elapsed,
eta).)doc");
}
