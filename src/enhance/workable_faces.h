// Internal to the enhance stage: the faces the methods and the metrics work on (enhance.h).
#pragma once

#include "vertexflow/mesh.h"

#include <vector>

namespace vertexflow::enhance_detail {

/// The faces with three distinct vertices, positive area (mesh.h's kDegenerateAreaRelative) that
/// repeat no earlier face, in order. The others stay in the face list, their vertices held.
std::vector<Index> workable_faces(const Mesh& mesh);

/// `F`'s rows `faces`.
Faces face_rows(const Faces& F, const std::vector<Index>& faces);

}  // namespace vertexflow::enhance_detail
