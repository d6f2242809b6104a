// Internal: faces that repeat an earlier face's vertex set, shared by the reader (which removes
// them, io.h) and the enhance engine (which holds their vertices, enhance.h).
#pragma once

#include "vertexflow/mesh.h"

#include <cstddef>
#include <vector>

namespace vertexflow {

/// Per face of `tris` (`num_faces` rows of 3 indices below `num_vertices`), 1 where the face has
/// the vertex set of an earlier face (any order or orientation), else 0. Faces are bucketed by
/// their smallest vertex (a counting sort, linear time), so only faces sharing that vertex are
/// compared; parallel, and the same for any thread count.
std::vector<char> find_duplicate_faces(const Index* tris, std::size_t num_faces, Index num_vertices);

}  // namespace vertexflow
