// The batch engine (batch.h): files through the enhance engine, jobs, resumable, summaries.
#include "vertexflow/batch.h"

#include "vertexflow/enhance_options.h"
#include "vertexflow/io.h"
#include "vertexflow/memory.h"
#include "vertexflow/timing.h"

#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <new>
#include <optional>
#include <system_error>
#include <thread>

#include <glob.h>

namespace vertexflow {
namespace {

// Why std::filesystem::exists (or is_directory) said no, given its error code: "no such file or
// directory" only when there is none; a loop of symbolic links, or a directory that may not be
// searched, is named for what it is.
std::string why_missing(const std::error_code& ec) {
  if (!ec || ec == std::errc::no_such_file_or_directory) return "no such file or directory";
  std::string message = ec.message();  // "Too many levels of symbolic links"
  if (!message.empty()) message[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(message[0])));
  return message;
}

std::string join(const std::vector<std::string>& parts) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : "; ") + p;
  return s;
}

// "FILE: problem", naming the file once.
std::string error_line(const std::filesystem::path& input, const std::string& what) {
  const std::string prefix = input.string() + ": ";
  return what.compare(0, prefix.size(), prefix) == 0 ? what : prefix + what;
}

// Reads a mesh, naming the file in the warnings; with `keep_faces`, its face list as it is
// (ReadOptions::keep_face_list), as `vertexflow enhance` reads its input.
Mesh read_with_warnings(const std::filesystem::path& path, std::vector<std::string>& warnings, bool keep_faces) {
  ReadReport report;
  ReadOptions options;
  options.keep_face_list = keep_faces;
  Mesh mesh = read_mesh(path, &report, options);
  for (const std::string& w : report.warnings()) warnings.push_back(w);
  return mesh;
}

// The metrics of enhance_metrics (`m`) into `row`.
void take_metrics(const nlohmann::json& m, BatchRow& row) {
  row.flipped_faces = m["flipped_faces"].get<long long>();
  row.rho_input = m["redistribution_rho"]["input"].get<double>();
  row.rho_result = m["redistribution_rho"]["result"].get<double>();
  row.cv_input = m["edge_error_cv"]["input"].get<double>();
  row.cv_result = m["edge_error_cv"]["result"].get<double>();
  row.displacement_mean = m["displacement_edge_lengths"]["mean"].get<double>();
  row.displacement_max = m["displacement_edge_lengths"]["max"].get<double>();
  if (m.contains("distance_to_reference")) {
    const auto& d = m["distance_to_reference"];
    row.distance_mean_input = d["input"]["mean"].get<double>();
    row.distance_mean_result = d["result"]["mean"].get<double>();
    row.hausdorff_input = d["input"]["hausdorff"].get<double>();
    row.hausdorff_result = d["result"]["hausdorff"].get<double>();
  }
}

// The reference surface of a file (none for an empty path), its reading warnings named.
std::optional<ReferenceSurface> read_reference(const std::filesystem::path& path, std::vector<std::string>& warnings) {
  std::optional<ReferenceSurface> reference;
  if (path.empty()) return reference;
  std::vector<std::string> reference_warnings;
  Mesh dense = read_with_warnings(path, reference_warnings, false);
  for (const std::string& w : reference_warnings) warnings.push_back(path.string() + ": " + w);
  reference.emplace(std::move(dense.V), std::move(dense.F), path.string());
  return reference;
}

void run_file(const std::filesystem::path& input, const std::filesystem::path& output,
              const std::filesystem::path& reference_path, const BatchFileOptions& options, BatchRow& row) {
  auto start = Clock::now();
  std::vector<std::string> warnings;
  const Mesh mesh = read_with_warnings(input, warnings, true);
  const std::optional<ReferenceSurface> reference = read_reference(reference_path, warnings);
  row.seconds_read = seconds_since(start);
  row.vertices = mesh.num_vertices();
  row.faces = mesh.num_faces();

  // A file that would not fit is this file's error, one line naming it, and the batch goes on;
  // where only the multilevel preconditioner would not fit, block-Jacobi alone runs, with a
  // warning (memory.h). With metrics, the estimate counts the report's peak, as `enhance
  // --report` does.
  EnhanceOptions enhance_options = options.enhance;
  const EnhanceMemoryPlan memory_plan = plan_memory_for_enhance(
      input.string(), mesh.num_vertices(), options.metrics,
      reference ? static_cast<Index>(reference->vertices().rows()) : 0, enhance_options.flow.solver);
  enhance_options.flow.solver = memory_plan.solver;
  if (!memory_plan.note.empty()) warnings.push_back(memory_plan.note);

  start = Clock::now();
  const ReferenceSurface* reference_pointer = reference ? &*reference : nullptr;
  EnhanceResult result;
  try {
    result = enhance(mesh, reference_pointer, enhance_options);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(error_line(input, e.what()));
  }
  row.seconds_enhance = seconds_since(start);
  row.mode = enhance_mode_name(result.mode);
  const nlohmann::json& guard = result.report.contains("guard") ? result.report["guard"] : nlohmann::json::object();
  row.limited_vertices = guard.contains("limited_vertices") ? guard["limited_vertices"].get<long long>() : -1;
  for (const std::string& w : result.warnings) warnings.push_back(w);
  row.warnings = join(warnings);

  // The bytes `vertexflow enhance` writes: the engine's mesh, write_mesh's defaults.
  start = Clock::now();
  const std::string lost = attributes_not_written_warning(result.mesh, format_from_path(output));
  if (!lost.empty()) {
    warnings.push_back(lost);
    row.warnings = join(warnings);
  }
  write_mesh(output, result.mesh);
  row.seconds_write = seconds_since(start);

  if (options.metrics) {
    start = Clock::now();
    take_metrics(enhance_metrics(mesh, result.mesh, reference_pointer), row);
    row.seconds_metrics = seconds_since(start);
  }
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

// The rows of an earlier summary in the output directory, by input path: a file skipped now keeps
// the measurements of the run that wrote its output. A missing summary gives none; an unreadable
// one (a run killed while writing it, a truncated copy) gives none and its `problem`, which the
// batch reports, since its skipped files are then measured again (take_measurements).
struct PreviousRows {
  std::map<std::string, nlohmann::json> rows;
  std::string problem;
};

PreviousRows previous_rows(const std::filesystem::path& json_path) {
  PreviousRows previous;
  std::error_code ec;
  if (!std::filesystem::exists(json_path, ec)) return previous;
  try {
    if (!std::filesystem::is_regular_file(json_path, ec)) throw IoError("not a regular file");
    std::ifstream in(json_path);
    const nlohmann::json summary = nlohmann::json::parse(in);
    for (const auto& row : summary.at("files"))
      if (row.at("status") == "done" || (row.at("status") == "skipped" && !row.at("vertices").is_null()))
        previous.rows[row.at("input").get<std::string>()] = row;
  } catch (const nlohmann::json::parse_error& e) {
    previous.rows.clear();
    previous.problem = fmt::format("not valid JSON (truncated or damaged at byte {})", e.byte);
  } catch (const std::exception& e) {
    previous.rows.clear();
    previous.problem = std::string("not a batch summary (") + e.what() + ")";
  }
  if (!previous.problem.empty())
    previous.problem = json_path.string() + ": cannot read the earlier summary: " + previous.problem +
                       "; the metrics of the files skipped are measured again from their inputs and outputs";
  return previous;
}

// `row` (skipped) with the measurements of `previous` (to_json's layout). False, and `row` left
// as it was, when `previous` is incomplete or is another output's row.
bool take_measurements(BatchRow& row, const nlohmann::json& previous) {
  const auto number = [](const nlohmann::json& j) { return j.is_number() ? j.get<double>() : std::nan(""); };
  const auto count = [](const nlohmann::json& j) { return j.is_number() ? j.get<long long>() : -1LL; };
  try {
    row.warnings = previous.at("warnings").get<std::string>();
    row.vertices = count(previous.at("vertices"));
    row.faces = count(previous.at("faces"));
    const auto& seconds = previous.at("seconds");
    row.seconds_read = number(seconds.at("read"));
    row.seconds_enhance = number(seconds.at("enhance"));
    row.seconds_write = number(seconds.at("write"));
    row.seconds_metrics = number(seconds.at("metrics"));
    row.seconds_total = number(seconds.at("total"));
    row.flipped_faces = count(previous.at("flipped_faces"));
    row.limited_vertices = count(previous.at("limited_vertices"));
    row.rho_input = number(previous.at("redistribution_rho").at("input"));
    row.rho_result = number(previous.at("redistribution_rho").at("result"));
    row.cv_input = number(previous.at("edge_error_cv").at("input"));
    row.cv_result = number(previous.at("edge_error_cv").at("result"));
    row.displacement_mean = number(previous.at("displacement_edge_lengths").at("mean"));
    row.displacement_max = number(previous.at("displacement_edge_lengths").at("max"));
    row.mode = previous.value("mode", "");
    if (previous.contains("distance_to_reference")) {
      const auto& d = previous.at("distance_to_reference");
      row.distance_mean_input = number(d.at("mean").at("input"));
      row.distance_mean_result = number(d.at("mean").at("result"));
      row.hausdorff_input = number(d.at("hausdorff").at("input"));
      row.hausdorff_result = number(d.at("hausdorff").at("result"));
    }
    if (previous.at("output").get<std::string>() != row.output) throw std::invalid_argument("another output");
  } catch (const std::exception&) {
    BatchRow fresh;  // an incomplete row: keep none of it
    fresh.input = row.input;
    fresh.output = row.output;
    fresh.reference = row.reference;
    fresh.status = row.status;
    fresh.seconds_total = row.seconds_total;
    row = fresh;
    return false;
  }
  return true;
}

// A skipped file without an earlier row to keep: its metrics measured from its input and the
// output on disk (what the run that wrote it measured, as the output is that run's mesh), so the
// summary has numbers for every output. The guard's limited_vertices, known only to that run,
// stay -1. An output that cannot be measured (not this input's vertices) keeps the row without
// metrics and says why in its warnings.
void measure_output(const BatchItem& item, const BatchFileOptions& options, const std::string& mode, BatchRow& row) {
  const auto start = Clock::now();
  std::vector<std::string> warnings;
  const auto measure = [&] {
    const Mesh input = read_with_warnings(item.input, warnings, true);
    std::vector<std::string> output_warnings;
    const Mesh output = read_with_warnings(item.output, output_warnings, true);
    for (const std::string& w : output_warnings) warnings.push_back(item.output.string() + ": " + w);
    const std::optional<ReferenceSurface> reference = read_reference(item.reference, warnings);
    row.seconds_read = seconds_since(start);
    row.vertices = input.num_vertices();
    row.faces = input.num_faces();
    const auto metrics_start = Clock::now();
    take_metrics(enhance_metrics(input, output, reference ? &*reference : nullptr), row);
    row.seconds_metrics = seconds_since(metrics_start);
    row.mode = mode;
  };
  try {
    if (options.threads > 0)
      tbb::task_arena(options.threads).execute(measure);
    else
      measure();
  } catch (const std::exception& e) {
    warnings.push_back("the existing output was not measured: " + error_line(item.output, e.what()));
  }
  row.warnings = join(warnings);
  row.seconds_total += seconds_since(start);
}

std::string csv_number(double x) {
  return std::isnan(x) ? std::string() : fmt::format("{:.6g}", x);
}
std::string csv_count(long long x) {
  return x < 0 ? std::string() : std::to_string(x);
}

}  // namespace

BatchRow enhance_file(const std::filesystem::path& input, const std::filesystem::path& output,
                      const BatchFileOptions& options, const std::filesystem::path& reference) {
  BatchRow row;
  row.input = input.string();
  row.output = output.string();
  row.reference = reference.string();
  const auto start = Clock::now();
  std::error_code ec;
  try {
    check_output_path(input, output, /*force=*/false, /*mesh_output=*/true);
    // A manifest may name outputs in directories of their own.
    if (output.has_parent_path() && !std::filesystem::exists(output.parent_path(), ec)) {
      std::filesystem::create_directories(output.parent_path(), ec);
      if (ec) throw IoError(output.string() + ": cannot create its directory: " + ec.message());
    }
    if (!reference.empty()) {
      check_output_path(reference, output, /*force=*/false, /*mesh_output=*/true);
      if (!std::filesystem::exists(reference, ec))
        throw IoError(reference.string() + ": " + why_missing(ec) + " (the reference of " + input.string() + ")");
    }
    if (!options.force && std::filesystem::exists(output, ec)) {
      row.status = "skipped";
      return row;
    }
    if (options.threads > 0) {
      tbb::task_arena arena(options.threads);
      arena.execute([&] { run_file(input, output, reference, options, row); });
    } else {
      run_file(input, output, reference, options, row);
    }
    row.status = "done";
  } catch (const std::bad_alloc&) {
    row.status = "failed";
    row.error = error_line(input, "out of memory");
  } catch (const std::exception& e) {
    row.status = "failed";
    row.error = error_line(input, e.what());
  }
  row.seconds_total = seconds_since(start);
  return row;
}

namespace {

// The fields of one CSV line (RFC 4180 quoting; no line breaks inside fields).
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"')
        fields.back() += '"', ++i;
      else if (c == '"')
        quoted = false;
      else
        fields.back() += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace

std::vector<BatchItem> read_batch_manifest(const std::filesystem::path& manifest) {
  std::ifstream in(manifest);
  if (!in) throw IoError(manifest.string() + ": cannot open the manifest");
  const std::filesystem::path base = manifest.parent_path();
  const auto resolve = [&](const std::string& p) {
    if (p.empty()) return std::filesystem::path();
    const std::filesystem::path path(p);
    return path.is_absolute() || base.empty() ? path : base / path;
  };
  std::vector<BatchItem> items;
  const std::string extension = lowercase_extension(manifest);
  if (extension == ".json") {
    nlohmann::json rows;
    try {
      rows = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw IoError(manifest.string() + ": not JSON: " + e.what());
    }
    if (!rows.is_array())
      throw IoError(manifest.string() + ": a JSON manifest is a list of {input, reference, output}");
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const nlohmann::json& row = rows[r];
      const auto field = [&](const char* key) -> std::string {
        if (!row.is_object() || !row.contains(key) || row[key].is_null()) return {};
        if (!row[key].is_string())
          throw IoError(fmt::format("{}: row {}: '{}' is not a path", manifest.string(), r, key));
        return row[key].get<std::string>();
      };
      if (field("input").empty()) throw IoError(fmt::format("{}: row {}: no input", manifest.string(), r));
      items.push_back({resolve(field("input")), resolve(field("reference")), resolve(field("output"))});
    }
    return items;
  }
  if (extension != ".csv") throw IoError(manifest.string() + ": a manifest is a .csv or .json file");
  std::string line;
  if (!std::getline(in, line))
    throw IoError(manifest.string() + ": empty manifest (a header line input,reference,output)");
  const std::vector<std::string> header = csv_fields(line);
  int input_column = -1, reference_column = -1, output_column = -1;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "input") input_column = static_cast<int>(c);
    if (header[c] == "reference") reference_column = static_cast<int>(c);
    if (header[c] == "output") output_column = static_cast<int>(c);
  }
  if (input_column < 0)
    throw IoError(manifest.string() + ": line 1: the header names no 'input' column (input,reference,output)");
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> fields = csv_fields(line);
    const auto at = [&](int column) {
      return column >= 0 && column < static_cast<int>(fields.size()) ? fields[column] : std::string();
    };
    if (at(input_column).empty()) throw IoError(fmt::format("{}: line {}: no input", manifest.string(), number));
    items.push_back({resolve(at(input_column)), resolve(at(reference_column)), resolve(at(output_column))});
  }
  return items;
}

namespace {

// Whether a directory entry or a glob match is an input, the same test in both modes: a mesh file
// name (a directory also holds summaries, reports and notes, and when it was a batch's output
// directory too, that batch's batch_summary.csv and .json), and not a directory. Any other kind
// of file is an input, not left out silently: a dangling link, a FIFO or a device fails as its
// row with read_mesh's reason (which opens without blocking and takes regular files only).
bool is_listed_input(const std::filesystem::path& path) {
  std::error_code ec;
  return is_mesh_path(path) && !std::filesystem::is_directory(path, ec);
}

}  // namespace

std::vector<std::filesystem::path> batch_inputs(const std::vector<std::string>& inputs) {
  std::vector<std::filesystem::path> files;
  for (const std::string& spec : inputs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec)) {
      std::vector<std::filesystem::path> in_dir;
      for (const auto& entry : std::filesystem::directory_iterator(spec, ec)) {
        const std::string name = entry.path().filename().string();
        if (!name.empty() && name[0] != '.' && is_listed_input(entry.path())) in_dir.push_back(entry.path());
      }
      if (ec) throw IoError(spec + ": cannot list the directory: " + ec.message());
      std::sort(in_dir.begin(), in_dir.end());
      files.insert(files.end(), in_dir.begin(), in_dir.end());
    } else if (spec.find_first_of("*?[") != std::string::npos) {
      glob_t g{};
      const int status = ::glob(spec.c_str(), 0, nullptr, &g);
      std::vector<std::filesystem::path> matched;
      for (std::size_t i = 0; status == 0 && i < g.gl_pathc; ++i)
        if (is_listed_input(g.gl_pathv[i])) matched.emplace_back(g.gl_pathv[i]);
      ::globfree(&g);
      if (matched.empty()) throw IoError(spec + ": matches no mesh file");
      files.insert(files.end(), matched.begin(), matched.end());
    } else {
      if (!std::filesystem::exists(spec, ec)) throw IoError(spec + ": " + why_missing(ec));
      files.emplace_back(spec);
    }
  }
  return files;
}

namespace {

// A mesh file's name without its extensions (".gz" and the format's): "bunny" for bunny.off.gz.
std::string mesh_stem(const std::filesystem::path& path) {
  const std::filesystem::path name = path.filename();
  return (is_gzip_path(name) ? name.stem() : name).stem().string();
}

// The mesh files of `directory` by stem, the first by name where several share one. Listed once
// for the whole batch, not once per input.
std::map<std::string, std::filesystem::path> references_by_stem(const std::filesystem::path& directory) {
  std::error_code ec;
  std::vector<std::filesystem::path> meshes;
  std::error_code entry_ec;  // an entry that cannot be looked at (a link loop) is no reference
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec))
    if (entry.is_regular_file(entry_ec) && is_mesh_path(entry.path())) meshes.push_back(entry.path());
  if (ec) throw IoError(directory.string() + ": cannot list the reference directory: " + ec.message());
  std::sort(meshes.begin(), meshes.end());
  std::map<std::string, std::filesystem::path> by_stem;
  for (const std::filesystem::path& mesh : meshes) by_stem.emplace(mesh_stem(mesh), mesh);
  return by_stem;
}

}  // namespace

std::vector<BatchItem> batch_items(const BatchOptions& options) {
  std::vector<BatchItem> items = options.items;
  if (items.empty())
    for (const std::filesystem::path& file : batch_inputs(options.inputs)) items.push_back({file, {}, {}});
  std::error_code ec;
  if (!options.reference_dir.empty() && !std::filesystem::is_directory(options.reference_dir, ec))
    throw IoError(options.reference_dir.string() + ": " + (ec ? why_missing(ec) : std::string("is not a directory")) +
                  " (the reference directory)");
  const std::map<std::string, std::filesystem::path> references = options.reference_dir.empty()
                                                                      ? std::map<std::string, std::filesystem::path>{}
                                                                      : references_by_stem(options.reference_dir);
  for (BatchItem& item : items) {
    if (item.output.empty()) item.output = options.output_dir / item.input.filename();
    if (const auto it = references.find(mesh_stem(item.input)); item.reference.empty() && it != references.end())
      item.reference = it->second;
  }
  return items;
}

BatchSummary run_batch(const BatchOptions& options) {
  if (options.jobs < 1) throw std::invalid_argument("jobs must be at least 1");
  if (options.file.threads < 0) throw std::invalid_argument("threads must be at least 0 (0: all cores)");
  if (options.output_dir.empty()) throw IoError("no output directory");
  const std::vector<BatchItem> items = batch_items(options);
  if (items.empty()) throw IoError("no input files");
  // The options' mode rules once for the batch: whether files have references decides the mode.
  // A batch runs in a reference mode when any file has a reference; then a file without one fails
  // (its error, not the batch's).
  const bool reference_mode =
      !options.reference_dir.empty() ||
      std::any_of(items.begin(), items.end(), [](const BatchItem& i) { return !i.reference.empty(); });
  validate_enhance_options(options.file.enhance, reference_mode, -1, options.naming);
  std::error_code ec;
  std::filesystem::create_directories(options.output_dir, ec);
  if (ec || !std::filesystem::is_directory(options.output_dir))
    throw IoError(options.output_dir.string() + ": cannot create the output directory" +
                  (ec ? ": " + ec.message() : std::string()));

  BatchFileOptions file_options = options.file;
  if (file_options.threads == 0)
    file_options.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / options.jobs);

  // One input per output: two inputs of the same file name (from different directories) would
  // write the same output; the later ones fail.
  const std::size_t count = items.size();
  std::map<std::filesystem::path, std::size_t> first_with_output;
  BatchSummary summary;
  summary.rows.resize(count);
  std::vector<bool> preset(count, false);
  for (std::size_t i = 0; i < count; ++i) {
    const BatchItem& item = items[i];
    const auto [it, fresh] = first_with_output.emplace(item.output.lexically_normal(), i);
    BatchRow& row = summary.rows[i];
    if (!fresh || (reference_mode && item.reference.empty())) {
      row.input = item.input.string();
      row.output = item.output.string();
      row.status = "failed";
      row.error = error_line(item.input, !fresh ? "has the same output as " + items[it->second].input.string() +
                                                      ", which it would overwrite"
                                                : "has no reference (a reference mode needs one per file)");
      preset[i] = true;
    }
  }

  const PreviousRows previous =
      options.write_summary ? previous_rows(options.output_dir / "batch_summary.json") : PreviousRows{};
  if (!previous.problem.empty() && options.warning) options.warning(previous.problem);
  const std::string mode_name = enhance_mode_name(enhance_mode(options.file.enhance, reference_mode));
  const auto start = Clock::now();
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::size_t finished = 0, failed = 0, processed = 0;
  double processed_seconds = 0;
  // What the progress callback threw: no file starts after it (see BatchOptions::progress).
  std::exception_ptr stop;
  std::atomic<bool> stopping{false};
  std::vector<char> reported(count, 0);
  auto worker = [&] {
    for (std::size_t i = next++; i < count && !stopping; i = next++) {
      if (!preset[i]) summary.rows[i] = enhance_file(items[i].input, items[i].output, file_options, items[i].reference);
      BatchRow& row = summary.rows[i];
      if (row.status == "skipped") {
        const auto it = previous.rows.find(row.input);
        const bool kept = it != previous.rows.end() && take_measurements(row, it->second) &&
                          (!file_options.metrics || !std::isnan(row.rho_result));
        if (!kept && file_options.metrics) measure_output(items[i], file_options, mode_name, row);
      }
      const std::lock_guard lock(mutex);
      reported[i] = 1;
      ++finished;
      if (row.status == "failed") ++failed;
      if (row.status != "skipped") {
        ++processed;
        processed_seconds += row.seconds_total;
      }
      if (options.progress) {
        BatchProgress p;
        p.finished = finished;
        p.total = count;
        p.failed = failed;
        p.row = &row;
        p.elapsed = seconds_since(start);
        // Files still to do at the mean time of the processed ones, spread over the jobs.
        if (processed > 0)
          p.eta = static_cast<double>(count - finished) * processed_seconds / static_cast<double>(processed) /
                  std::min<double>(options.jobs, std::max<std::size_t>(1, count - finished));
        if (!stop) {
          try {
            options.progress(p);
          } catch (...) {
            stop = std::current_exception();
            stopping = true;
          }
        }
      }
    }
  };
  const int jobs = std::min<int>(options.jobs, static_cast<int>(count));
  {
    std::vector<std::jthread> threads;
    for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
    worker();
  }
  summary.seconds = seconds_since(start);
  if (stop) {
    // The files finished are kept, on disk and in the summary, so a rerun resumes after them.
    std::vector<BatchRow> finished_rows;
    for (std::size_t i = 0; i < count; ++i)
      if (reported[i]) finished_rows.push_back(std::move(summary.rows[i]));
    summary.rows = std::move(finished_rows);
  }
  for (const BatchRow& row : summary.rows) {
    if (row.status == "done") ++summary.done;
    if (row.status == "skipped") ++summary.skipped;
    if (row.status == "failed") ++summary.failed;
  }

  if (options.write_summary) {
    nlohmann::json j;
    j["done"] = summary.done;
    j["skipped"] = summary.skipped;
    j["failed"] = summary.failed;
    j["seconds"] = summary.seconds;
    j["jobs"] = options.jobs;
    j["threads_per_job"] = file_options.threads;
    j["mode"] = mode_name;
    if (stop) j["stopped"] = "the progress callback raised an exception: the files not listed did not run";
    j["options"] = enhance_options_json(options.file.enhance);
    j["files"] = nlohmann::json::array();
    for (const BatchRow& row : summary.rows) j["files"].push_back(to_json(row));
    summary.csv = options.output_dir / "batch_summary.csv";
    summary.json = options.output_dir / "batch_summary.json";
    write_text_file(summary.csv, batch_csv(summary.rows));
    write_text_file(summary.json, j.dump(2) + "\n");
  }
  if (stop) std::rethrow_exception(stop);
  return summary;
}

nlohmann::json to_json(const BatchRow& row) {
  const auto number = [](double x) { return std::isnan(x) ? nlohmann::json(nullptr) : nlohmann::json(x); };
  const auto count = [](long long x) { return x < 0 ? nlohmann::json(nullptr) : nlohmann::json(x); };
  return {
      {"input", row.input},
      {"output", row.output},
      {"reference", row.reference.empty() ? nlohmann::json(nullptr) : nlohmann::json(row.reference)},
      {"mode", row.mode.empty() ? nlohmann::json(nullptr) : nlohmann::json(row.mode)},
      {"status", row.status},
      {"error", row.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(row.error)},
      {"warnings", row.warnings},
      {"vertices", count(row.vertices)},
      {"faces", count(row.faces)},
      {"seconds",
       {{"read", row.seconds_read},
        {"enhance", row.seconds_enhance},
        {"write", row.seconds_write},
        {"metrics", row.seconds_metrics},
        {"total", row.seconds_total}}},
      {"flipped_faces", count(row.flipped_faces)},
      {"limited_vertices", count(row.limited_vertices)},
      {"redistribution_rho", {{"input", number(row.rho_input)}, {"result", number(row.rho_result)}}},
      {"edge_error_cv", {{"input", number(row.cv_input)}, {"result", number(row.cv_result)}}},
      {"displacement_edge_lengths", {{"mean", number(row.displacement_mean)}, {"max", number(row.displacement_max)}}},
      {"distance_to_reference",
       {{"mean", {{"input", number(row.distance_mean_input)}, {"result", number(row.distance_mean_result)}}},
        {"hausdorff", {{"input", number(row.hausdorff_input)}, {"result", number(row.hausdorff_result)}}}}}};
}

std::string batch_csv(const std::vector<BatchRow>& rows) {
  std::string s =
      "input,output,reference,mode,status,vertices,faces,seconds_read,seconds_enhance,seconds_write,seconds_metrics,"
      "seconds_total,flipped_faces,limited_vertices,rho_input,rho_result,cv_input,cv_result,displacement_mean,"
      "displacement_max,distance_mean_input,distance_mean_result,hausdorff_input,hausdorff_result,error,warnings\n";
  for (const BatchRow& r : rows)
    s += fmt::format(
        "{},{},{},{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
        csv_field(r.input), csv_field(r.output), csv_field(r.reference), r.mode, r.status, csv_count(r.vertices),
        csv_count(r.faces), r.seconds_read, r.seconds_enhance, r.seconds_write, r.seconds_metrics, r.seconds_total,
        csv_count(r.flipped_faces), csv_count(r.limited_vertices), csv_number(r.rho_input), csv_number(r.rho_result),
        csv_number(r.cv_input), csv_number(r.cv_result), csv_number(r.displacement_mean),
        csv_number(r.displacement_max), csv_number(r.distance_mean_input), csv_number(r.distance_mean_result),
        csv_number(r.hausdorff_input), csv_number(r.hausdorff_result), csv_field(r.error), csv_field(r.warnings));
  return s;
}

}  // namespace vertexflow
