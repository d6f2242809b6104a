// The enhance engine (enhance.h) on numpy arrays, and the option table it takes (options.h).
// The package's vertexflow.enhance is a Python function whose signature is built from the table;
// it calls _enhance with the keywords the caller gave.
#include "options.h"

#include "vertexflow/enhance_options.h"
#include "vertexflow/io.h"
#include "vertexflow/memory.h"
#include "vertexflow/reference_surface.h"

#include <chrono>
#include <optional>

namespace vertexflow::python {
namespace {

// The reference: a pair (V, F), unnamed (its provenance line says '?'), or a mesh file's path,
// read as the CLI's --reference reads it and named by it.
std::optional<ReferenceSurface> reference_from(const py::object& reference) {
  if (reference.is_none()) return std::nullopt;
  if (py::isinstance<py::str>(reference) || py::hasattr(reference, "__fspath__")) {
    const std::string path = fspath(reference);
    Mesh dense;
    {
      py::gil_scoped_release release;
      dense = read_mesh(path);
    }
    return ReferenceSurface(std::move(dense.V), std::move(dense.F), path);
  }
  if (!py::isinstance<py::tuple>(reference) && !py::isinstance<py::list>(reference))
    throw py::value_error("reference must be a pair (V, F) of the dense mesh, or its file's path");
  const py::sequence pair = reference.cast<py::sequence>();
  if (pair.size() != 2) throw py::value_error("reference must be a pair (V, F) of the dense mesh, or its file's path");
  Mesh dense = to_mesh(pair[0], pair[1], "reference V", "reference F");
  return ReferenceSurface(std::move(dense.V), std::move(dense.F));
}

// (V_out[, F_out][, attributes_out], report): F_out with the option that changes the faces,
// attributes_out when the caller gave attributes (re-sampled where vertices moved).
py::tuple py_enhance(const py::handle& V, const py::handle& F, const py::dict& given, const py::object& reference,
                     const py::object& provenance, const py::object& attributes, int threads,
                     const py::object& progress) {
  EnhanceOptions options = enhance_options_from(given, "enhance");
  check_threads(threads);
  Mesh mesh = to_mesh(V, F);
  // Smooth mode reads the input's provenance from its comments, as the CLI's does from the file.
  mesh.comments = string_lines(provenance, "provenance");
  // Seams and label boundaries are creases, and the channels are re-sampled, as for the CLI's
  // input (enhance.h).
  mesh.attributes = attributes_from_python(attributes, mesh.num_vertices(), mesh.num_faces());
  const bool has_reference = !reference.is_none();
  validate_enhance_options(options, has_reference, mesh.num_vertices(), OptionNaming::Python);
  const std::optional<ReferenceSurface> dense = reference_from(reference);
  // A run that would not fit raises MemoryError now, one line, rather than the OOM killer later;
  // where only the multilevel preconditioner would not fit, block-Jacobi alone runs and the
  // report's warnings say so (memory.h). The arrays have no path; "enhance" names the call. No
  // report's metrics here.
  const EnhanceMemoryPlan memory_plan =
      plan_memory_for_enhance("enhance", mesh.num_vertices(), /*with_report=*/false,
                              dense ? static_cast<Index>(dense->vertices().rows()) : 0, options.flow.solver);
  options.flow.solver = memory_plan.solver;

  const char* mode = enhance_mode_name(enhance_mode(options, has_reference));
  if (!progress.is_none())
    progress("enhance: " + std::string(mode) + " on " + std::to_string(mesh.num_vertices()) + " vertices");
  EnhanceResult result = without_gil(threads, [&] { return enhance(mesh, dense ? &*dense : nullptr, options); });
  if (!progress.is_none()) progress("enhance: done");

  nlohmann::json report = std::move(result.report);
  if (!memory_plan.note.empty()) result.warnings.insert(result.warnings.begin(), memory_plan.note);
  report["warnings"] = result.warnings;
  py::list out;
  out.append(to_numpy(std::move(result.mesh.V)));
  if (options.edge_flips) out.append(to_numpy(std::move(result.mesh.F)));
  if (!attributes.is_none()) out.append(attributes_to_python(std::move(result.mesh.attributes)));
  out.append(to_python(report));
  return py::tuple(out);
}

// Every option's value (enhance_options_json) after the checks enhance makes for a run with or
// without a reference; errors name the options as Python keywords or CLI flags.
py::dict py_enhance_options(const py::dict& given, bool has_reference, const std::string& naming) {
  if (naming != "python" && naming != "cli")
    throw py::value_error("naming: '" + naming + "' is not one of python, cli");
  const OptionNaming names = naming == "cli" ? OptionNaming::Cli : OptionNaming::Python;
  const EnhanceOptions options = enhance_options_from(given, "enhance_options", names);
  validate_enhance_options(options, has_reference, -1, names);
  return to_python(enhance_options_json(options));
}

// The mode `options` choose, or "" for a combination the engine refuses.
std::string mode_of(const EnhanceOptions& options, bool has_reference) {
  try {
    return enhance_mode_name(enhance_mode(options, has_reference));
  } catch (const EnhanceOptionError&) {
    return {};
  }
}

// Which options choose each mode, found by asking the engine (enhance_mode) about the defaults
// and every choice of every Choice option, without and with a reference: {name, reference,
// options} per mode.
py::tuple enhance_mode_table() {
  const auto choose = [](const std::string& mode) -> py::object {
    for (const bool has_reference : {false, true}) {
      const auto entry = [&](const py::dict& options) {
        return py::dict(py::arg("name") = mode, py::arg("reference") = has_reference, py::arg("options") = options);
      };
      if (mode_of(EnhanceOptions{}, has_reference) == mode) return entry(py::dict());
      for (const EnhanceOptionSpec& spec : enhance_option_specs()) {
        for (const std::string_view choice : spec.choices) {
          EnhanceOptions options;
          spec.set(options, std::string(choice));
          if (mode_of(options, has_reference) != mode) continue;
          py::dict selected;
          selected[py::str(spec.name.data(), spec.name.size())] = py::str(choice.data(), choice.size());
          return entry(selected);
        }
      }
    }
    return py::none();  // chosen by no single option: left out
  };
  py::list table;
  for (const py::handle name : enhance_mode_names()) {
    py::object entry = choose(name.cast<std::string>());
    if (!entry.is_none()) table.append(entry);
  }
  return py::tuple(table);
}

// The option that changes the faces (EnhanceOptions::edge_flips), found through the table: with
// it, enhance returns (V, F, report).
std::string faces_option() {
  EnhanceOptions flipped;
  flipped.edge_flips = true;
  const EnhanceOptions defaults;
  for (const EnhanceOptionSpec& spec : enhance_option_specs())
    if (spec.get(flipped) != spec.get(defaults)) return std::string(spec.name);
  return {};
}

// For bench/python_overhead.py: the wall-clock seconds of `repeats` calls of the engine, as
// vertexflow.enhance(V, F) makes it, from C++ on a mesh already converted (what a C++ program
// pays), without the GIL.
std::vector<double> py_time_enhance(const py::handle& V, const py::handle& F, int repeats, int threads) {
  const Mesh mesh = to_mesh(V, F);
  std::vector<double> seconds;
  without_gil(threads, [&] {
    for (int i = 0; i < repeats; ++i) {
      const auto start = std::chrono::steady_clock::now();
      const EnhanceResult r = enhance(mesh, nullptr, EnhanceOptions{});
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  });
  return seconds;
}

}  // namespace

void register_enhance(py::module_& m) {
  m.def("_enhance_option_table", &enhance_option_table,
        "The option table of enhance_options.h, one dict per option (vertexflow/_options.py reads it).");
  m.def("_enhance_mode_names", &enhance_mode_names, "The names of the enhance modes, in the order of EnhanceMode.");
  m.def("_enhance_mode_table", &enhance_mode_table, "Which options choose each mode: {name, reference, options}.");
  m.attr("_FACES_OPTION") = faces_option();
  m.def("_enhance", &py_enhance, py::arg("V"), py::arg("F"), py::arg("options"), py::arg("reference") = py::none(),
        py::arg("provenance") = py::none(), py::arg("attributes") = py::none(), py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        "vertexflow.enhance's work: options is {keyword: value} of the keywords given.");
  m.def("_enhance_options", &py_enhance_options, py::arg("options"), py::arg("has_reference") = false,
        py::arg("naming") = "python", "vertexflow.enhance_options's work.");
  m.def(
      "_estimated_enhance_peak_bytes",
      [](Index vertices, bool block_jacobi_alone) {
        return estimated_enhance_peak_bytes(vertices, false, 0,
                                            block_jacobi_alone ? LinearSolver::Iterative : LinearSolver::Automatic);
      },
      py::arg("vertices"), py::arg("block_jacobi_alone") = false,
      "memory.h's estimate of enhance's peak on a mesh of `vertices` (bytes), for the tests of the refusal.");
  m.def("_time_vertex_flow", &py_time_enhance, py::arg("V"), py::arg("F"), py::arg("repeats") = 1,
        py::arg("threads") = 0,
        "Seconds of each of `repeats` calls of the enhance engine made from C++, as vertexflow.enhance(V, F) makes "
        "it (bench/python_overhead.py).");
}

}  // namespace vertexflow::python
