// Closest-point queries against their peer: vertexflow::DistanceQuery (CGAL's AABB tree,
// distance.h) and Embree 3's rtcPointQuery (Debian's libembree-dev) on the same points, timed,
// checked against each other and checked for answers that depend on the thread count. The fit's
// closest-point queries are about 40% of the wall time of `vertexflow lod` on a 1M-vertex mesh
// (docs/lod.md); this measures what a faster tree would save, with the fit's two kinds of query:
//
//   A: N area samples of DENSE (sample_surface, no vertices or edge midpoints, along a Morton
//      curve) against COARSE, as the fit draws samples of the reference;
//   B: COARSE's vertices (index order), then its face centroids (face order), against DENSE.
//
//   build/bin/point_query_peers /tmp/vf29/arm_loop1m.off /tmp/lodR1/arm_loop1m_lod1_1000656.off
//       --runs 3 --threads 2,1
//
// (DENSE = a lod input, COARSE = its first level.) For each thread count (tbb::global_control)
// and each of the runs: the build and the query time of each method, wall and process CPU
// seconds; medians are printed as a Markdown table (stdout), and every run with --json OUT.
//
// Embree: one triangle geometry (a float copy of V, our F shared as the index buffer), build
// quality MEDIUM; every query's callback computes the exact closest point in double from our V
// and F, keeps the smallest (squared distance, face index) and shrinks the query radius; each
// query starts from the previous answer's face (in fixed blocks of points). Its answer is the
// lexicographic minimum over all faces, so it does not depend on the BVH, the hints or the
// thread count; the program checks that (a hash of its faces and distances per thread count)
// and that its squared distances equal DistanceQuery's within 1e-12 of the target's bounding-box
// diagonal squared, and exits with 1 when either fails.
//
// Options: --samples N (A's samples, default 5000000); --runs R (default 3); --threads 2,1 (the
// thread counts, in that order; default: the machine's); --json OUT.
#include "vertexflow/distance.h"
#include "vertexflow/io.h"
#include "vertexflow/mesh.h"
#include "vertexflow/timing.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace vertexflow;

// ---- Timing and small helpers ----------------------------------------------------------------

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The 1-minute load average: the machine may be shared, and the table says so.
double load_average() {
  double load = -1;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = -1;
    std::fclose(f);
  }
  return load;
}

struct Seconds {
  double wall = 0, cpu = 0;
};

class Stopwatch {
 public:
  [[nodiscard]] Seconds elapsed() const { return {seconds_since(wall_), cpu_seconds() - cpu_}; }

 private:
  Clock::time_point wall_ = Clock::now();
  double cpu_ = cpu_seconds();
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// One method's runs on one query set at one thread count.
struct Runs {
  std::vector<double> build, query, build_cpu, query_cpu;
  void add(Seconds b, Seconds q) {
    build.push_back(b.wall);
    build_cpu.push_back(b.cpu);
    query.push_back(q.wall);
    query_cpu.push_back(q.cpu);
  }
  [[nodiscard]] nlohmann::json json() const {
    return {{"build", build}, {"query", query}, {"build_cpu", build_cpu}, {"query_cpu", query_cpu}};
  }
};

// Answers of one method: squared distance and face per query point.
struct Answers {
  std::vector<double> d2;
  std::vector<Index> face;
};

// FNV-1a over the faces and the bits of the squared distances.
std::uint64_t hash_answers(const Answers& a) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](std::uint64_t word) {
    h ^= word;
    h *= 1099511628211ull;
  };
  for (std::size_t i = 0; i < a.d2.size(); ++i) {
    std::uint64_t bits;
    std::memcpy(&bits, &a.d2[i], sizeof bits);
    mix(static_cast<std::uint32_t>(a.face[i]));
    mix(bits);
  }
  return h;
}

// ---- Exact closest point on a triangle, in double ----------------------------------------------

using Point = Eigen::Vector3d;

Point closest_on_segment(const Point& p, const Point& a, const Point& b) {
  const Point ab = b - a;
  const double length2 = ab.squaredNorm();
  if (!(length2 > 0)) return a;
  return a + std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) * ab;
}

// Ericson, Real-Time Collision Detection, 5.1.5. A degenerate triangle (a zero denominator) is
// taken as the closest of its three edges, as DistanceQuery takes it as its longest edge.
Point closest_on_triangle(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Point bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) return a + (d1 / (d1 - d3)) * ab;
  const Point cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0 && (d4 - d3) + (d5 - d6) > 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double sum = va + vb + vc;
  if (sum > 0) return a + (vb / sum) * ab + (vc / sum) * ac;
  Point best = closest_on_segment(p, a, b);
  for (const Point& q : {closest_on_segment(p, b, c), closest_on_segment(p, c, a)})
    if ((p - q).squaredNorm() < (p - best).squaredNorm()) best = q;
  return best;
}

// ---- Embree ------------------------------------------------------------------------------------

// A float radius that Embree's float traversal cannot use to cull a box holding a triangle whose
// double distance to the query is sqrt(d2). Embree stores float vertices, rounds the query point
// to float and compares float box distances with radius^2: each vertex and the query point are
// off by up to sqrt(3) ulps of the largest coordinate, and the box distance adds a few ulps, so
// `margin` = 16 ulps of it (2^-24 relative) plus a relative 1e-6, rounded up to a float. With a
// radius of exactly sqrt(d2) Embree could skip a face as close as the best, or one closer.
float conservative_radius(double d2, double margin) {
  const double r = (std::sqrt(d2) + margin) * (1.0 + 1e-6);
  float f = static_cast<float>(r);
  if (static_cast<double>(f) < r) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

class EmbreeDevice {
 public:
  // nullptr, not "threads=N": Debian's Embree uses TBB, and "threads=N" makes a process-wide
  // tbb::global_control that caps every TBB loop of the process (ours too) until the device is
  // released. Without it Embree's builds run under the caller's tbb::global_control, as ours do.
  EmbreeDevice() : device_(rtcNewDevice(nullptr)) {
    if (!device_) throw std::runtime_error("rtcNewDevice failed");
    rtcSetDeviceErrorFunction(device_, &EmbreeDevice::on_error, nullptr);
  }
  ~EmbreeDevice() { rtcReleaseDevice(device_); }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  [[nodiscard]] RTCDevice get() const { return device_; }
  // Throws if an Embree call on this thread failed since the last check.
  void check(const char* what) const {
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error(fmt::format("embree: {} failed", what));
  }

 private:
  static void on_error(void*, RTCError code, const char* message) {
    std::cerr << fmt::format("point_query_peers: embree error {}: {}\n", static_cast<int>(code), message);
  }
  RTCDevice device_;
};

// One query's state, the callback's userPtr.
struct Query {
  Point p;
  const Vertices* V;
  const Faces* F;
  double margin;
  double best_d2 = std::numeric_limits<double>::infinity();
  double radius2 = std::numeric_limits<double>::infinity();  // the query radius, squared, in double
  Index best_face = std::numeric_limits<Index>::max();

  [[nodiscard]] double squared_distance_to(Index f) const {
    return (p - closest_on_triangle(p, V->row(F->coeff(f, 0)).transpose(), V->row(F->coeff(f, 1)).transpose(),
                                    V->row(F->coeff(f, 2)).transpose()))
        .squaredNorm();
  }
  // Takes face f at squared distance d2 if it beats the best; returns the new radius, or 0.
  float offer(Index f, double d2) {
    // Exact ties go to the lower face index: then the answer is the minimum of (d2, face) over
    // all faces, whatever order the traversal meets them in (BVH, hints, threads).
    if (d2 < best_d2 || (d2 == best_d2 && f < best_face)) {
      best_d2 = d2;
      best_face = f;
      const float r = conservative_radius(d2, margin);
      radius2 = static_cast<double>(r) * static_cast<double>(r);
      return r;
    }
    return 0;
  }
};

bool point_query_callback(RTCPointQueryFunctionArguments* args) {
  auto& q = *static_cast<Query*>(args->userPtr);
  const auto f = static_cast<Index>(args->primID);
  // Embree calls back for every triangle of a visited leaf, with no test of its own. A face whose
  // double bounding box is beyond the radius cannot be as close as the best: skip it before the
  // projection (about 5% of the query time in the experiment). Against the conservative radius,
  // not the best d2, so that the projection's rounding cannot make a skipped face the answer.
  double box2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double x0 = (*q.V)(q.F->coeff(f, 0), k), x1 = (*q.V)(q.F->coeff(f, 1), k), x2 = (*q.V)(q.F->coeff(f, 2), k);
    const double d = std::max({0.0, std::min({x0, x1, x2}) - q.p[k], q.p[k] - std::max({x0, x1, x2})});
    box2 += d * d;
  }
  if (box2 > q.radius2) return false;
  const float r = q.offer(f, q.squared_distance_to(f));
  if (r > 0 && r < args->query->radius) {
    args->query->radius = r;
    return true;
  }
  return false;
}

// An Embree scene over (V, F), which must outlive it unchanged (F is shared, not copied).
class EmbreeScene {
 public:
  EmbreeScene(const EmbreeDevice& device, const Vertices& V, const Faces& F, double max_abs_coordinate)
      : V_(V), F_(F), margin_(16.0 * std::ldexp(1.0, -24) * max_abs_coordinate), scene_(rtcNewScene(device.get())) {
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geometry = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
    // Embree's triangles are float: a copy (part of the timed build). Embree pads the buffer.
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), static_cast<std::size_t>(V.rows())));
    device.check("vertex buffer");
    const double* source = V.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, static_cast<std::size_t>(V.size())),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i)
                          vertices[i] = static_cast<float>(source[i]);
                      });
    // Faces are rows of three int32: Embree's UINT3 layout, shared as they are.
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, F.data(), 0, 3 * sizeof(Index),
                               static_cast<std::size_t>(F.rows()));
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
    device.check("scene build");
  }
  ~EmbreeScene() { rtcReleaseScene(scene_); }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // The closest face of every row of P, in parallel over fixed blocks of points: in a block each
  // query but the first starts from the previous answer's face, its distance and radius. The
  // start matters beyond the usual better bound: Embree 3.13's descent tests child boxes against
  // the query's initial radius (the shrunk one only culls nodes popped from its stack).
  [[nodiscard]] Answers closest_faces(const Vertices& P) const {
    constexpr std::size_t kBlock = 256;
    const auto n = static_cast<std::size_t>(P.rows());
    Answers answers{std::vector<double>(n), std::vector<Index>(n)};
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, (n + kBlock - 1) / kBlock, 1),
        [&](const tbb::blocked_range<std::size_t>& blocks) {
          for (std::size_t block = blocks.begin(); block != blocks.end(); ++block) {
            Index previous = -1;
            for (std::size_t i = block * kBlock; i < std::min(n, (block + 1) * kBlock); ++i) {
              Query q{P.row(static_cast<Index>(i)).transpose(), &V_, &F_, margin_};
              // Both structs must be 16-byte aligned (RTC_ALIGN(16); said here as well).
              alignas(16) RTCPointQuery query{};
              query.x = static_cast<float>(q.p.x());
              query.y = static_cast<float>(q.p.y());
              query.z = static_cast<float>(q.p.z());
              query.radius = std::numeric_limits<float>::infinity();
              if (previous >= 0) query.radius = q.offer(previous, q.squared_distance_to(previous));
              alignas(16) RTCPointQueryContext context;
              rtcInitPointQueryContext(&context);
              rtcPointQuery(scene_, &query, &context, point_query_callback, &q);
              answers.d2[i] = q.best_d2;
              answers.face[i] = previous = q.best_face;
            }
          }
        },
        tbb::simple_partitioner());
    return answers;
  }

 private:
  const Vertices& V_;
  const Faces& F_;
  double margin_;  // conservative_radius's absolute slack
  RTCScene scene_;
};

// ---- The query sets ------------------------------------------------------------------------

struct QuerySet {
  std::string name, description, target_name;
  const Mesh* target;
  Vertices points;
};

Vertices vertices_and_centroids(const Mesh& m) {
  Vertices points(m.V.rows() + m.F.rows(), 3);
  points.topRows(m.V.rows()) = m.V;
  for (Index f = 0; f < m.F.rows(); ++f)
    points.row(m.V.rows() + f) = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))) / 3.0;
  return points;
}

// Per query set and thread count: both methods' runs and how their answers compare.
struct Outcome {
  int threads = 0;
  Runs ours, embree;
  double max_relative_difference = 0;  // max |d2 ours - d2 Embree| / diag^2 of the target
  std::size_t face_differences = 0;
  std::uint64_t ours_hash = 0, embree_hash = 0;
};

Outcome measure(const QuerySet& set, const EmbreeDevice& device, int threads, int runs) {
  const tbb::global_control control(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  const Mesh& target = *set.target;
  const double max_abs = std::max(target.V.cwiseAbs().maxCoeff(), set.points.cwiseAbs().maxCoeff());
  Outcome outcome;
  outcome.threads = threads;
  Answers ours, embree;
  for (int run = 0; run < runs; ++run) {
    // The two methods alternate, so that a change of the machine's load hits both.
    Stopwatch watch;
    const DistanceQuery tree(target.V, target.F, DistanceQuery::Borrow{});
    const Seconds build = watch.elapsed();
    watch = Stopwatch();
    const std::vector<ClosestPoint> closest = tree.closest_points(set.points);
    outcome.ours.add(build, watch.elapsed());
    ours.d2.resize(closest.size());
    ours.face.resize(closest.size());
    for (std::size_t i = 0; i < closest.size(); ++i) {
      ours.d2[i] = closest[i].squared_distance;
      ours.face[i] = closest[i].face;
    }

    watch = Stopwatch();
    const EmbreeScene scene(device, target.V, target.F, max_abs);
    const Seconds embree_build = watch.elapsed();
    watch = Stopwatch();
    embree = scene.closest_faces(set.points);
    outcome.embree.add(embree_build, watch.elapsed());
    std::cerr << fmt::format(
        "point_query_peers: {}, {} thread(s), run {}/{}: DistanceQuery {:.2f} + {:.2f} s, "
        "Embree {:.2f} + {:.2f} s (build + query, wall; load {:.2f})\n",
        set.name, threads, run + 1, runs, outcome.ours.build.back(), outcome.ours.query.back(),
        outcome.embree.build.back(), outcome.embree.query.back(), load_average());
  }
  const double diag2 = std::pow(bounding_box(target.V).diagonal(), 2);
  for (std::size_t i = 0; i < ours.d2.size(); ++i) {
    outcome.max_relative_difference =
        std::max(outcome.max_relative_difference, std::abs(ours.d2[i] - embree.d2[i]) / diag2);
    if (ours.face[i] != embree.face[i]) ++outcome.face_differences;
  }
  outcome.ours_hash = hash_answers(ours);
  outcome.embree_hash = hash_answers(embree);
  return outcome;
}

// ---- Arguments -----------------------------------------------------------------------------

[[noreturn]] void fail_usage(const std::string& message) {
  std::cerr << "point_query_peers: " << message << "\n";
  std::exit(2);
}

long parse_positive(const std::string& option, const std::string& text) {
  long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value <= 0)
    fail_usage(fmt::format("{} needs a positive integer, not '{}'", option, text));
  return value;
}

std::vector<int> parse_threads(const std::string& text) {
  std::vector<int> counts;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const long n = parse_positive("--threads", item);
    if (n > 1024) fail_usage(fmt::format("--threads: {} threads?", n));
    counts.push_back(static_cast<int>(n));
  }
  if (counts.empty()) fail_usage("--threads needs a list such as 2,1");
  return counts;
}

}  // namespace

int main(int argc, char** argv) {
  Index samples = 5000000;
  int runs = 3;
  std::vector<int> thread_counts = {static_cast<int>(tbb::info::default_concurrency())};
  std::string json_path;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) fail_usage(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--samples") {
      const long n = parse_positive(arg, next());
      if (n > std::numeric_limits<Index>::max()) fail_usage(fmt::format("--samples: {} is too many", n));
      samples = static_cast<Index>(n);
    } else if (arg == "--runs") {
      runs = static_cast<int>(std::min(parse_positive(arg, next()), 1000L));
    } else if (arg == "--threads") {
      thread_counts = parse_threads(next());
    } else if (arg == "--json") {
      json_path = next();
    } else if (!arg.empty() && arg[0] == '-') {
      fail_usage("unknown option " + arg);
    } else {
      paths.push_back(arg);
    }
  }
  if (paths.size() != 2) {
    std::cerr << "usage: point_query_peers DENSE COARSE [--samples N] [--runs R] [--threads 2,1] [--json OUT]\n";
    return 2;
  }

  try {
    const double load_before = load_average();
    const Mesh dense = read_mesh(paths[0]);
    const Mesh coarse = read_mesh(paths[1]);
    for (std::size_t k = 0; k < 2; ++k)
      if ((k == 0 ? dense : coarse).F.rows() == 0) throw std::runtime_error(paths[k] + ": no faces");

    SamplingOptions sampling;
    sampling.samples = samples;
    sampling.vertices = false;
    sampling.edge_midpoints = false;
    std::vector<QuerySet> sets;
    sets.push_back({"A", fmt::format("{} area samples of DENSE", samples), "COARSE", &coarse,
                    sample_surface(dense.V, dense.F, sampling).points});
    sets.push_back({"B", fmt::format("COARSE's {} vertices and {} face centroids", coarse.V.rows(), coarse.F.rows()),
                    "DENSE", &dense, vertices_and_centroids(coarse)});

    const EmbreeDevice device;
    const long embree_version = static_cast<long>(rtcGetDeviceProperty(device.get(), RTC_DEVICE_PROPERTY_VERSION));
    // outcomes[s][t]: query set s at thread count t.
    std::vector<std::vector<Outcome>> outcomes(sets.size());
    for (const int threads : thread_counts)
      for (std::size_t s = 0; s < sets.size(); ++s) outcomes[s].push_back(measure(sets[s], device, threads, runs));
    const double load_after = load_average();

    // Checks: equal distances, and Embree's answers the same for every thread count.
    std::vector<std::string> failures;
    for (std::size_t s = 0; s < sets.size(); ++s)
      for (const Outcome& o : outcomes[s]) {
        if (o.max_relative_difference > 1e-12)
          failures.push_back(fmt::format("query set {} at {} thread(s): squared distances differ by {:.3g} of diag^2",
                                         sets[s].name, o.threads, o.max_relative_difference));
        if (o.embree_hash != outcomes[s][0].embree_hash)
          failures.push_back(fmt::format("query set {}: Embree's answers at {} thread(s) differ from those at {}",
                                         sets[s].name, o.threads, outcomes[s][0].threads));
      }

    std::ostringstream md;
    md << "## Closest-point queries: vertexflow::DistanceQuery (CGAL AABB tree) against Embree's rtcPointQuery\n\n"
       << fmt::format(
              "Generated by `build/bin/point_query_peers` (bench/point_query_peers.cpp). DENSE = {} ({} "
              "vertices, {} faces), COARSE = {} ({} vertices, {} faces). Query set A: {} -> COARSE; B: {} -> "
              "DENSE. Embree {}.{}.{}, build quality MEDIUM, hints from the previous answer. Seconds, median "
              "of {} run(s): wall (process CPU). Load average (1 min) {:.2f} before, {:.2f} after.\n\n",
              paths[0], dense.V.rows(), dense.F.rows(), paths[1], coarse.V.rows(), coarse.F.rows(), sets[0].description,
              sets[1].description, embree_version / 10000, embree_version / 100 % 100, embree_version % 100, runs,
              load_before, load_after);
    md << fmt::format("| threads | method | build COARSE | query A ({} points) | build DENSE | query B ({} points) |\n",
                      sets[0].points.rows(), sets[1].points.rows())
       << "|---:|---|---:|---:|---:|---:|\n";
    const auto cell = [](const std::vector<double>& wall, const std::vector<double>& cpu) {
      return fmt::format("{:.2f} ({:.2f})", median(wall), median(cpu));
    };
    const auto ratio = [](const std::vector<double>& ours, const std::vector<double>& embree) {
      return fmt::format("{:.2f}x", median(ours) / median(embree));
    };
    for (std::size_t t = 0; t < thread_counts.size(); ++t) {
      const Outcome &a = outcomes[0][t], &b = outcomes[1][t];
      md << fmt::format("| {} | DistanceQuery | {} | {} | {} | {} |\n", a.threads, cell(a.ours.build, a.ours.build_cpu),
                        cell(a.ours.query, a.ours.query_cpu), cell(b.ours.build, b.ours.build_cpu),
                        cell(b.ours.query, b.ours.query_cpu));
      md << fmt::format("| {} | Embree | {} | {} | {} | {} |\n", a.threads, cell(a.embree.build, a.embree.build_cpu),
                        cell(a.embree.query, a.embree.query_cpu), cell(b.embree.build, b.embree.build_cpu),
                        cell(b.embree.query, b.embree.query_cpu));
      md << fmt::format("| {} | DistanceQuery / Embree (wall) | {} | {} | {} | {} |\n", a.threads,
                        ratio(a.ours.build, a.embree.build), ratio(a.ours.query, a.embree.query),
                        ratio(b.ours.build, b.embree.build), ratio(b.ours.query, b.embree.query));
    }
    md << "\n| query set | max \\|d2 ours - d2 Embree\\| / diag^2 | faces differing (ties) | Embree's answers, "
          "hash | the same for every thread count |\n|---|---:|---:|---|---|\n";
    for (std::size_t s = 0; s < sets.size(); ++s) {
      double worst = 0;
      std::size_t differing = 0;
      bool same = true;
      for (const Outcome& o : outcomes[s]) {
        worst = std::max(worst, o.max_relative_difference);
        differing = std::max(differing, o.face_differences);
        same = same && o.embree_hash == outcomes[s][0].embree_hash;
      }
      md << fmt::format("| {} | {:.3g} | {} of {} | {:016x} | {} |\n", sets[s].name, worst, differing,
                        sets[s].points.rows(), outcomes[s][0].embree_hash, same ? "yes" : "**no**");
    }
    std::cout << md.str();

    if (!json_path.empty()) {
      nlohmann::json json = {{"dense", paths[0]},
                             {"coarse", paths[1]},
                             {"samples", samples},
                             {"runs", runs},
                             {"embree_version", embree_version},
                             {"load_before", load_before},
                             {"load_after", load_after},
                             {"ok", failures.empty()},
                             {"failures", failures}};
      for (std::size_t s = 0; s < sets.size(); ++s) {
        nlohmann::json per_threads = nlohmann::json::array();
        for (const Outcome& o : outcomes[s])
          per_threads.push_back({{"threads", o.threads},
                                 {"distance_query", o.ours.json()},
                                 {"embree", o.embree.json()},
                                 {"max_relative_d2_difference", o.max_relative_difference},
                                 {"face_differences", o.face_differences},
                                 {"distance_query_hash", fmt::format("{:016x}", o.ours_hash)},
                                 {"embree_hash", fmt::format("{:016x}", o.embree_hash)}});
        json["query_sets"][sets[s].name] = {{"description", sets[s].description},
                                            {"target", sets[s].target_name},
                                            {"points", sets[s].points.rows()},
                                            {"target_faces", sets[s].target->F.rows()},
                                            {"results", per_threads}};
      }
      std::ofstream out(json_path);
      out << json.dump(1) << "\n";
      if (!out) throw std::runtime_error(json_path + ": cannot write");
    }
    for (const std::string& failure : failures) std::cerr << "point_query_peers: FAILED: " << failure << "\n";
    return failures.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "point_query_peers: " << e.what() << "\n";
    return 1;
  }
}
