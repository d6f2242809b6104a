// Internal: the zero set of a per-vertex scalar over a triangle mesh as chained polylines, the
// machinery every line type of lines.h shares.
#pragma once

#include "vertexflow/lines.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace vertexflow::lines_detail {

/// One end of a face's segment: on an edge (its key, shared by the faces on both sides, so
/// chains continue there) or a free end where a test clipped the segment (edge = -1).
struct SegmentEnd {
  std::int64_t edge = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

/// The piece of the zero set inside one face, if any.
struct FaceSegment {
  bool present = false;
  std::array<SegmentEnd, 2> end;
};

/// What to extract. g and keep are per vertex; the zero set of g is kept where keep, linearly
/// interpolated, is >= 0 (segments are clipped where it crosses 0). `align(a, b)` is +1 or -1:
/// the factor that makes g[b] comparable with g[a] (for values whose sign depends on a
/// per-vertex direction, such as D_T1 k1); it must be symmetric. `face_test(f, g0, g1, g2)`,
/// given the face's values aligned to its first corner, may reject a face's segment.
struct ZeroSetInput {
  const Eigen::VectorXd* g = nullptr;
  const Eigen::VectorXd* keep = nullptr;
  std::function<double(Index a, Index b)> align;
  std::function<bool(Index f, double g0, double g1, double g2)> face_test;
};

/// The zero set's polylines, typed `type`, in face order of their first segment.
std::vector<Polyline> zero_set(const Vertices& V, const Faces& F, const ZeroSetInput& input, LineType type);

/// Throws std::invalid_argument (prefixed by `what`) when a face index is out of range or
/// `per_vertex_rows` (each a row count that must equal #V) does not match.
void check_line_input(const Vertices& V, const Faces& F, std::initializer_list<Eigen::Index> per_vertex_rows,
                      const char* what);

}  // namespace vertexflow::lines_detail
