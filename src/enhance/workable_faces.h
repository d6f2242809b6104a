// Internal to the enhance stage: the faces the methods and the metrics work on, and what a run
// keeps for the metrics (enhance.h).
#pragma once

#include "vertexflow/enhance.h"
#include "vertexflow/mesh.h"
#include "vertexflow/topology.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace vertexflow::enhance_detail {

/// The faces with three distinct vertices, positive area (mesh.h's kDegenerateAreaRelative) that
/// repeat no earlier face, in order. The others stay in the face list, their vertices held.
/// When `topology` is given and every face has three distinct vertices and positive area, it
/// receives build_topology(mesh.F, mesh.num_vertices()), which then proves the faces distinct
/// where no edge has more than two faces (a face repeating another shares all three edges with
/// it), without find_duplicate_faces' sort; otherwise it is left empty.
std::vector<Index> workable_faces(const Mesh& mesh, std::optional<Topology>* topology = nullptr);

/// `F`'s rows `faces`.
Faces face_rows(const Faces& F, const std::vector<Index>& faces);

/// A 64-bit fingerprint of a face list (its size and every index, in order).
std::uint64_t faces_fingerprint(const Faces& F);

}  // namespace vertexflow::enhance_detail

namespace vertexflow {

/// EnhanceMetricsReuse's content (enhance.h).
struct EnhanceMetricsReuse::Kept {
  /// build_topology(faces, vertices) of the input, as the flow left it (flow.h): every face of
  /// the input workable, so the metrics' faces are these.
  Topology topology;
  std::uint64_t faces = 0;  ///< enhance_detail::faces_fingerprint of the input's F
};

}  // namespace vertexflow
