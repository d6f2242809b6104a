#include "command_batch_core.h"

#include "report_support.h"

#include "vertexflow/io.h"
#include "vertexflow/provenance.h"
#include "vertexflow/report_json.h"
#include "vertexflow/timing.h"
#include "vertexflow/topology.h"

#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>
#include <new>
#include <system_error>
#include <thread>

#include <glob.h>

namespace vertexflow::cli {
namespace {

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

void run_file(const std::filesystem::path& input, const std::filesystem::path& output, const BatchFileOptions& options,
              BatchRow& row) {
  auto start = Clock::now();
  ReadReport read_report;
  Mesh mesh = read_mesh(input, &read_report);
  row.seconds_read = seconds_since(start);
  std::vector<std::string> warnings = read_report.warnings();
  row.vertices = mesh.num_vertices();
  row.faces = mesh.num_faces();

  start = Clock::now();
  const Topology topology = build_topology(mesh.F, mesh.num_vertices());
  FlowResult result;
  try {
    result = vertex_flow(mesh.V, mesh.F, topology, options.flow);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(error_line(input, e.what()));
  }
  row.seconds_enhance = seconds_since(start);
  const FlowReport& r = result.report;
  row.limited_vertices = r.limited_vertices;
  if (r.held_non_manifold_vertices + r.reoriented_faces + r.cut_edges > 0)
    warnings.push_back(
        fmt::format("not manifold or not consistently oriented: {} vertices held, {} faces reoriented, "
                    "{} edges treated as boundaries",
                    r.held_non_manifold_vertices, r.reoriented_faces, r.cut_edges));
  row.warnings = join(warnings);

  // As `vertexflow enhance`: same connectivity and colours, no vertex properties, the input's
  // comments and the paper's flow's provenance line (provenance.h).
  Mesh out;
  out.V = std::move(result.V);
  out.F = mesh.F;
  out.colors = mesh.colors;
  out.comments = mesh.comments;
  append_provenance(out.comments, provenance_line({}));
  start = Clock::now();
  write_mesh(output, out);
  row.seconds_write = seconds_since(start);

  if (options.metrics) {
    start = Clock::now();
    const ReportCurvatures curvatures = report_curvatures(mesh, out, topology);
    const nlohmann::json m = flow_metrics(mesh, out, topology, curvatures);
    row.flipped_faces = m["flipped_faces"].get<long long>();
    row.rho_input = m["redistribution_rho"]["input"].get<double>();
    row.rho_result = m["redistribution_rho"]["result"].get<double>();
    row.cv_input = m["edge_error_cv"]["input"].get<double>();
    row.cv_result = m["edge_error_cv"]["result"].get<double>();
    row.displacement_mean = m["displacement_edge_lengths"]["mean"].get<double>();
    row.displacement_max = m["displacement_edge_lengths"]["max"].get<double>();
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
// the measurements of the run that wrote its output. A missing or unreadable summary gives none.
std::map<std::string, nlohmann::json> previous_rows(const std::filesystem::path& json_path) {
  std::map<std::string, nlohmann::json> rows;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(json_path, ec)) return rows;
  try {
    std::ifstream in(json_path);
    const nlohmann::json summary = nlohmann::json::parse(in);
    for (const auto& row : summary.at("files"))
      if (row.at("status") == "done" || (row.at("status") == "skipped" && !row.at("vertices").is_null()))
        rows[row.at("input").get<std::string>()] = row;
  } catch (const std::exception&) {
    rows.clear();  // not ours, or damaged: start afresh
  }
  return rows;
}

// `row` (skipped) with the measurements of `previous` (to_json's layout).
void take_measurements(BatchRow& row, const nlohmann::json& previous) {
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
  } catch (const std::exception&) {
    const BatchRow fresh;
    row.vertices = fresh.vertices;  // an incomplete row: keep none of it
    row.faces = fresh.faces;
  }
}

std::string csv_number(double x) {
  return std::isnan(x) ? std::string() : fmt::format("{:.6g}", x);
}
std::string csv_count(long long x) {
  return x < 0 ? std::string() : std::to_string(x);
}

}  // namespace

BatchRow enhance_file(const std::filesystem::path& input, const std::filesystem::path& output,
                      const BatchFileOptions& options) {
  BatchRow row;
  row.input = input.string();
  row.output = output.string();
  const auto start = Clock::now();
  std::error_code ec;
  try {
    check_output_path(input, output, /*force=*/false, /*mesh_output=*/true);
    if (!options.force && std::filesystem::exists(output, ec)) {
      row.status = "skipped";
      return row;
    }
    if (options.threads > 0) {
      tbb::task_arena arena(options.threads);
      arena.execute([&] { run_file(input, output, options, row); });
    } else {
      run_file(input, output, options, row);
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

std::vector<std::filesystem::path> batch_inputs(const std::vector<std::string>& inputs) {
  std::vector<std::filesystem::path> files;
  for (const std::string& spec : inputs) {
    std::error_code ec;
    if (std::filesystem::is_directory(spec, ec)) {
      std::vector<std::filesystem::path> in_dir;
      for (const auto& entry : std::filesystem::directory_iterator(spec, ec)) {
        const std::string name = entry.path().filename().string();
        if (!name.empty() && name[0] != '.' && entry.is_regular_file(ec)) in_dir.push_back(entry.path());
      }
      if (ec) throw IoError(spec + ": cannot list the directory: " + ec.message());
      std::sort(in_dir.begin(), in_dir.end());
      files.insert(files.end(), in_dir.begin(), in_dir.end());
    } else if (spec.find_first_of("*?[") != std::string::npos) {
      glob_t g{};
      const int status = ::glob(spec.c_str(), 0, nullptr, &g);
      std::vector<std::filesystem::path> matched;
      for (std::size_t i = 0; status == 0 && i < g.gl_pathc; ++i)
        if (!std::filesystem::is_directory(g.gl_pathv[i], ec)) matched.emplace_back(g.gl_pathv[i]);
      ::globfree(&g);
      if (matched.empty()) throw IoError(spec + ": matches no file");
      files.insert(files.end(), matched.begin(), matched.end());
    } else {
      if (!std::filesystem::exists(spec, ec)) throw IoError(spec + ": no such file or directory");
      files.emplace_back(spec);
    }
  }
  return files;
}

BatchSummary run_batch(const BatchOptions& options) {
  if (options.jobs < 1) throw std::invalid_argument("jobs must be at least 1");
  if (options.file.threads < 0) throw std::invalid_argument("threads must be at least 0 (0: all cores)");
  validate_flow_options(options.file.flow);
  const std::vector<std::filesystem::path> files = batch_inputs(options.inputs);
  if (files.empty()) throw IoError("no input files");
  if (options.output_dir.empty()) throw IoError("no output directory");
  std::error_code ec;
  std::filesystem::create_directories(options.output_dir, ec);
  if (ec || !std::filesystem::is_directory(options.output_dir))
    throw IoError(options.output_dir.string() + ": cannot create the output directory" +
                  (ec ? ": " + ec.message() : std::string()));

  BatchFileOptions file_options = options.file;
  if (file_options.threads == 0)
    file_options.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / options.jobs);

  // One output per name: two inputs of the same file name (from different directories) would
  // write the same output; the later ones fail.
  std::vector<std::filesystem::path> outputs;
  std::map<std::string, std::size_t> first_with_name;
  BatchSummary summary;
  summary.rows.resize(files.size());
  std::vector<bool> preset(files.size(), false);
  for (std::size_t i = 0; i < files.size(); ++i) {
    outputs.push_back(options.output_dir / files[i].filename());
    const auto [it, fresh] = first_with_name.emplace(files[i].filename().string(), i);
    if (!fresh) {
      BatchRow& row = summary.rows[i];
      row.input = files[i].string();
      row.output = outputs[i].string();
      row.status = "failed";
      row.error = error_line(
          files[i], "has the same file name as " + files[it->second].string() + ", whose output it would overwrite");
      preset[i] = true;
    }
  }

  const std::map<std::string, nlohmann::json> previous = options.write_summary
                                                             ? previous_rows(options.output_dir / "batch_summary.json")
                                                             : std::map<std::string, nlohmann::json>{};
  const auto start = Clock::now();
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  std::size_t finished = 0, failed = 0, processed = 0;
  double processed_seconds = 0;
  auto worker = [&] {
    for (std::size_t i = next++; i < files.size(); i = next++) {
      if (!preset[i]) summary.rows[i] = enhance_file(files[i], outputs[i], file_options);
      BatchRow& row = summary.rows[i];
      if (row.status == "skipped") {
        const auto it = previous.find(row.input);
        if (it != previous.end()) take_measurements(row, it->second);
      }
      const std::lock_guard lock(mutex);
      ++finished;
      if (row.status == "failed") ++failed;
      if (row.status != "skipped") {
        ++processed;
        processed_seconds += row.seconds_total;
      }
      if (options.progress) {
        BatchProgress p;
        p.finished = finished;
        p.total = files.size();
        p.failed = failed;
        p.row = &row;
        p.elapsed = seconds_since(start);
        // Files still to do at the mean time of the processed ones, spread over the jobs.
        if (processed > 0)
          p.eta = static_cast<double>(files.size() - finished) * processed_seconds / static_cast<double>(processed) /
                  std::min<double>(options.jobs, std::max<std::size_t>(1, files.size() - finished));
        options.progress(p);
      }
    }
  };
  const int jobs = std::min<int>(options.jobs, static_cast<int>(files.size()));
  {
    std::vector<std::jthread> threads;
    for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
    worker();
  }
  summary.seconds = seconds_since(start);
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
    j["options"] = options.file.flow;
    j["files"] = nlohmann::json::array();
    for (const BatchRow& row : summary.rows) j["files"].push_back(to_json(row));
    summary.csv = options.output_dir / "batch_summary.csv";
    summary.json = options.output_dir / "batch_summary.json";
    write_text_file(summary.csv, batch_csv(summary.rows));
    write_text_file(summary.json, j.dump(2) + "\n");
  }
  return summary;
}

nlohmann::json to_json(const BatchRow& row) {
  const auto number = [](double x) { return std::isnan(x) ? nlohmann::json(nullptr) : nlohmann::json(x); };
  const auto count = [](long long x) { return x < 0 ? nlohmann::json(nullptr) : nlohmann::json(x); };
  return {
      {"input", row.input},
      {"output", row.output},
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
      {"displacement_edge_lengths", {{"mean", number(row.displacement_mean)}, {"max", number(row.displacement_max)}}}};
}

std::string batch_csv(const std::vector<BatchRow>& rows) {
  std::string s =
      "input,output,status,vertices,faces,seconds_read,seconds_enhance,seconds_write,seconds_metrics,seconds_total,"
      "flipped_faces,limited_vertices,rho_input,rho_result,cv_input,cv_result,displacement_mean,displacement_max,"
      "error,warnings\n";
  for (const BatchRow& r : rows)
    s += fmt::format(
        "{},{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{},{},{},{},{},{},{},{}\n", csv_field(r.input),
        csv_field(r.output), r.status, csv_count(r.vertices), csv_count(r.faces), r.seconds_read, r.seconds_enhance,
        r.seconds_write, r.seconds_metrics, r.seconds_total, csv_count(r.flipped_faces), csv_count(r.limited_vertices),
        csv_number(r.rho_input), csv_number(r.rho_result), csv_number(r.cv_input), csv_number(r.cv_result),
        csv_number(r.displacement_mean), csv_number(r.displacement_max), csv_field(r.error), csv_field(r.warnings));
  return s;
}

}  // namespace vertexflow::cli
