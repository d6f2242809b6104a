// The batch engine (batch.h): enhance_file, batch, and the manifest and input lists they read.
// The package's vertexflow.enhance_file and vertexflow.batch are Python functions whose
// signatures are built from the option table; they call _enhance_file and _batch.
#include "options.h"

#include "vertexflow/batch.h"

#include <pybind11/stl/filesystem.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vertexflow::python {
namespace {

py::object path_or_none(const std::filesystem::path& path) {
  return path.empty() ? py::object(py::none()) : py::object(py::str(path.string()));
}

// `has_reference`: check the mode's rules here (enhance_file); none: run_batch checks them.
BatchFileOptions file_options(const py::dict& given, std::optional<bool> has_reference, bool force, bool metrics,
                              int threads, const char* function) {
  BatchFileOptions options;
  options.enhance = enhance_options_from(given, function);
  // The mode's rules in the keywords' names, before any file is read.
  if (has_reference) validate_enhance_options(options.enhance, *has_reference, -1, OptionNaming::Python);
  options.force = force;
  options.metrics = metrics;
  check_threads(threads);
  options.threads = threads;
  return options;
}

py::dict py_enhance_file(const py::handle& input, const py::handle& output, const py::dict& given,
                         const py::object& reference, bool force, bool metrics, int threads) {
  const BatchFileOptions options = file_options(given, !reference.is_none(), force, metrics, threads, "enhance_file");
  const std::filesystem::path in = fspath(input), out = fspath(output);
  const std::filesystem::path dense =
      reference.is_none() ? std::filesystem::path() : std::filesystem::path(fspath(reference));
  BatchRow row;
  {
    py::gil_scoped_release release;
    row = enhance_file(in, out, options, dense);
  }
  return to_python(to_json(row));
}

std::vector<std::string> input_specs(const py::object& inputs) {
  if (py::isinstance<py::str>(inputs) || py::hasattr(inputs, "__fspath__")) return {fspath(inputs)};
  std::vector<std::string> specs;
  for (const py::handle item : inputs) specs.push_back(fspath(item));
  return specs;
}

py::dict py_batch(const py::object& inputs, const py::object& output_dir, const py::dict& given,
                  const py::object& manifest, const py::object& reference_dir, int jobs, int threads, bool force,
                  bool metrics, const py::object& progress) {
  if (output_dir.is_none()) throw py::type_error("batch() missing the output directory: output_dir");
  if (inputs.is_none() == manifest.is_none())
    throw py::value_error(inputs.is_none() ? "batch: give inputs (directories, globs or files) or manifest"
                                           : "batch: give inputs or manifest, not both");
  BatchOptions options;
  if (!manifest.is_none())
    options.items = read_batch_manifest(fspath(manifest));
  else
    options.inputs = input_specs(inputs);
  if (!reference_dir.is_none()) options.reference_dir = fspath(reference_dir);
  options.output_dir = fspath(output_dir);
  options.jobs = jobs;
  // run_batch checks the mode's rules, in the keywords' names, before any file is read.
  options.naming = OptionNaming::Python;
  options.file = file_options(given, std::nullopt, force, metrics, threads, "batch");
  // Warnings about the batch as a whole (an unreadable earlier summary), raised as UserWarnings
  // once the GIL is held again.
  std::vector<std::string> warnings;
  options.warning = [&warnings](const std::string& warning) { warnings.push_back(warning); };
  // What the progress callback raised (KeyboardInterrupt included), or a signal (Ctrl-C) found
  // pending after a file: run_batch stops at the next file boundary, keeps what was written and
  // rethrows Stop, and the Python exception is raised again here.
  struct Stop {};
  auto raised = std::make_shared<std::optional<py::error_already_set>>();
  options.progress = [progress, raised](const BatchProgress& p) {
    py::gil_scoped_acquire acquire;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!progress.is_none()) {
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
      }
    } catch (py::error_already_set& e) {
      *raised = std::move(e);
      throw Stop{};
    }
  };
  BatchSummary summary;
  try {
    py::gil_scoped_release release;
    summary = run_batch(options);
  } catch (const Stop&) {
    throw std::move(**raised);
  }
  for (const std::string& warning : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
  py::dict d;
  py::list rows;
  for (const auto& row : summary.rows) rows.append(to_python(to_json(row)));
  d["files"] = rows;
  d["done"] = summary.done;
  d["skipped"] = summary.skipped;
  d["failed"] = summary.failed;
  d["seconds"] = summary.seconds;
  d["csv"] = summary.csv.string();
  d["json"] = summary.json.string();
  return d;
}

py::list py_read_batch_manifest(const py::handle& manifest) {
  py::list rows;
  for (const BatchItem& item : read_batch_manifest(fspath(manifest)))
    rows.append(py::dict(py::arg("input") = item.input.string(), py::arg("reference") = path_or_none(item.reference),
                         py::arg("output") = path_or_none(item.output)));
  return rows;
}

py::list py_batch_inputs(const py::object& inputs) {
  py::list files;
  for (const std::filesystem::path& file : batch_inputs(input_specs(inputs))) files.append(file.string());
  return files;
}

}  // namespace

void register_batch(py::module_& m) {
  m.def("_enhance_file", &py_enhance_file, py::arg("input"), py::arg("output"), py::arg("options"),
        py::arg("reference") = py::none(), py::arg("force") = false, py::arg("metrics") = true, py::arg("threads") = 0,
        "vertexflow.enhance_file's work: options is {keyword: value} of the keywords given.");
  m.def("_batch", &py_batch, py::arg("inputs"), py::arg("output_dir"), py::arg("options"),
        py::arg("manifest") = py::none(), py::arg("reference_dir") = py::none(), py::arg("jobs") = 1,
        py::arg("threads") = 0, py::arg("force") = false, py::arg("metrics") = true, py::arg("progress") = py::none(),
        "vertexflow.batch's work: options is {keyword: value} of the keywords given.");
  m.def("read_batch_manifest", &py_read_batch_manifest, py::arg("manifest"),
        R"doc(The rows of a batch manifest, as `vertexflow batch --manifest` reads them (batch.h) ->
[{"input", "reference", "output"}]: CSV with a header naming the columns input, reference and
output, or JSON, a list of objects with those keys; reference and output may be missing (None).
Relative paths are taken relative to the manifest's directory. Raises OSError naming the line
(or row) of a problem.)doc");
  m.def("batch_inputs", &py_batch_inputs, py::arg("inputs"),
        R"doc(The input files of `vertexflow batch IN` for a directory (its mesh files, sorted), a glob
pattern (sorted), a file, or a list of them -> [path]. Raises OSError for a pattern that matches
nothing or a path that does not exist.)doc");
}

}  // namespace vertexflow::python
