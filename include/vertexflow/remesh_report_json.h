// The JSON of a remesh (remesh.h): what `vertexflow remesh --json` prints, besides the file
// names, and what the Python module's remesh(..., report=True) returns as a dict. Written once
// here so that the two agree (python/tests/test_remesh.py compares them).
//
// Conventions as in report_json.h: every field under its own name, except where stated.
#pragma once

#include "vertexflow/manifold_split.h"
#include "vertexflow/remesh.h"

#include <nlohmann/json.hpp>

namespace vertexflow {

/// {input_split_vertices, input_reoriented_faces, input_cut_edges (the ManifoldSplitCounts of
/// input_split), removed_degenerate_faces, duplicated_vertices}.
nlohmann::json surface_repairs_json(const SurfaceRepairs& repairs);

/// Every field of RemeshCleanup; short_loops is written as "short_loops_kept".
nlohmann::json remesh_cleanup_json(const RemeshCleanup& cleanup);

/// One flat object: input_vertices, vertices and faces (of result.mesh); target_vertices,
/// tolerance and within_tolerance when `searched` (the result of remesh_to_vertex_count; not
/// for remesh_to_edge_length); edge_length, runs ([{edge_length, vertices, seconds}] per
/// attempt), iterations, protect_boundary, seconds; quality, quality_interior and quality_rim
/// (to_json of QualityStats), interior_faces, rim_faces, components, boundary_loops,
/// non_manifold_vertices, zero_area_faces and min_edge_length (RemeshQuality);
/// small_piece_edges, short_loop_edges and fill_hole_edges (the options); cleanup
/// (remesh_cleanup_json) and repairs (surface_repairs_json). `options` are those of the run
/// (for remesh_to_edge_length only options.isotropic is read).
nlohmann::json remesh_report_json(const RemeshResult& result, Index input_vertices, const RemeshOptions& options,
                                  bool searched);

}  // namespace vertexflow
