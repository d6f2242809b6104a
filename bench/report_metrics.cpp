// The report's metrics alone (enhance_metrics, the `--report` of `vertexflow enhance`), timed
// and with their own peak memory, for issue 29: the flow's result is read from a file, so a
// metrics change is measured without running the flow again.
//
//   build/bin/vertexflow enhance /tmp/vf29/arm1m.ply /tmp/vf29/o1m.ply
//   build/bin/report_metrics /tmp/vf29/arm1m.ply /tmp/vf29/o1m.ply [--threads N] [--metrics]
//
// Prints one JSON object: "seconds" (enhance_metrics' wall time), "cpu_seconds" (its user and
// system time: on a shared machine, steadier than the wall), "rss_before_mib" (the
// process after reading both meshes), "peak_rss_mib" (the peak during enhance_metrics: the
// kernel's high-water mark, reset after the reads) and with --metrics the report's figures
// (for diffing two builds; "seconds" of the figures is not there).
#include "vertexflow/enhance.h"
#include "vertexflow/io.h"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

namespace {

// VmRSS or VmHWM of this process, in MiB.
double status_mib(const std::string& key) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  return -1;
}

// User and system CPU time of this process, in seconds.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

}  // namespace

int main(int argc, char** argv) {
  std::string paths[2];
  int given = 0;
  int threads = 0;
  bool print_metrics = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--threads" && i + 1 < argc) {
      threads = std::stoi(argv[++i]);
    } else if (arg == "--metrics") {
      print_metrics = true;
    } else if (given < 2 && (arg.empty() || arg[0] != '-')) {
      paths[given++] = arg;
    } else {
      std::cerr << "usage: report_metrics INPUT RESULT [--threads N] [--metrics]\n";
      return 2;
    }
  }
  if (given != 2) {
    std::cerr << "usage: report_metrics INPUT RESULT [--threads N] [--metrics]\n";
    return 2;
  }
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  try {
    const vertexflow::Mesh input = vertexflow::read_mesh(paths[0]);
    const vertexflow::Mesh result = vertexflow::read_mesh(paths[1]);
    const double before = status_mib("VmRSS");
    // "5" resets the high-water mark VmHWM to the current RSS (proc(5), clear_refs).
    std::ofstream("/proc/self/clear_refs") << "5";
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = cpu_seconds();
    vertexflow::EnhanceCurvatures curvatures;  // as the CLI asks for them (its HTML report)
    nlohmann::json metrics = vertexflow::enhance_metrics(input, result, nullptr, &curvatures);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = cpu_seconds() - cpu_start;
    nlohmann::json out = {{"vertices", input.num_vertices()},
                          {"seconds", seconds},
                          {"cpu_seconds", cpu},
                          {"rss_before_mib", before},
                          {"peak_rss_mib", status_mib("VmHWM")}};
    if (print_metrics) out["metrics"] = std::move(metrics);
    std::cout << out.dump(1) << '\n';
  } catch (const std::exception& e) {
    std::cerr << "report_metrics: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
