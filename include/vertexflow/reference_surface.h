// A dense mesh of the true surface S, built once per command and shared by everything that
// measures against it: reference mode's fit (fit.h), the edge flips' target (edge_flips.h) and
// the report's two-sided distances (enhance.h). Its closest-point tree is built on first use,
// once, and its surface samples once per sampling (count, seed, kinds), so a command that fits,
// flips, refits and reports builds one tree of S instead of one per step.
//
// The paper's flow on S (vertex_flow_on_reference, flow.h) builds its own tree and curvature of
// S in the flow's normalised units (translated to the input's centroid, scaled to its mean edge
// length 1): its closest points are computed there, and sharing this tree (in S's own units)
// would change its results by rounding.
//
// Thread-safe: every accessor may be called from several threads at once; the lazily built
// parts are built by the first caller while the others wait.
#pragma once

#include "vertexflow/distance.h"
#include "vertexflow/mesh.h"

#include <cstddef>
#include <memory>
#include <string>

namespace vertexflow {

class ReferenceSurface {
 public:
  /// S as (V, F), in the units of the meshes measured against it; `name` (a file path, or
  /// empty) is what provenance lines and reports call it. Throws std::invalid_argument for an
  /// empty S or a non-finite coordinate.
  ReferenceSurface(Vertices V, Faces F, std::string name = {});
  ~ReferenceSurface();
  ReferenceSurface(ReferenceSurface&&) noexcept;
  ReferenceSurface& operator=(ReferenceSurface&&) noexcept;
  ReferenceSurface(const ReferenceSurface&) = delete;
  ReferenceSurface& operator=(const ReferenceSurface&) = delete;

  [[nodiscard]] const Vertices& vertices() const;
  [[nodiscard]] const Faces& faces() const;
  [[nodiscard]] const std::string& name() const;

  /// The closest-point tree over S's faces (distance.h), built on the first call.
  [[nodiscard]] const DistanceQuery& distance_query() const;
  /// Samples of S (sample_surface, distance.h) for `options`, drawn on the first call with
  /// these options and kept.
  [[nodiscard]] const SurfaceSamples& samples(const SamplingOptions& options = {}) const;

  /// How many times S's tree has been built (1 after any use, 0 before): what the reports
  /// record as reference_trees_built, and what the tests hold at 1.
  [[nodiscard]] int trees_built() const;

  /// The bytes S holds now: its V and F, its tree once built (DistanceQuery::memory_bytes) and
  /// the samples drawn so far. What reports record as reference_memory_bytes.
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vertexflow
