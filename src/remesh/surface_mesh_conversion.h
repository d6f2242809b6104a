// Conversion between vertexflow's V/F matrices and CGAL::Surface_mesh, shared by the stages that
// run CGAL halfedge algorithms (simplify.cpp, remesh.cpp). Not installed: CGAL types stay out of
// the public headers.
#pragma once

#include "vertexflow/manifold_split.h"
#include "vertexflow/mesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <string>

namespace vertexflow::remesh_detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

/// A Surface_mesh with the vertices of V (same order, including unreferenced ones) and the
/// faces of F (same order and orientation). A mesh that is not manifold or not consistently
/// oriented, which a halfedge mesh cannot represent, is converted through its manifold split
/// (manifold_split.h: non-manifold vertices duplicated, non-manifold edges cut, faces oriented
/// per component); `split` (if given) receives its counts, all 0 for a manifold, oriented mesh.
/// `stage` prefixes the error messages ("simplify"). Throws std::invalid_argument for an empty
/// mesh or an index out of range.
SurfaceMesh to_surface_mesh(const Vertices& V, const Faces& F, const std::string& stage,
                            ManifoldSplitCounts* split = nullptr);

/// V/F of `mesh`: removed elements (garbage) and vertices without faces are skipped, the others
/// keep their relative order and the faces their orientation. Before that, what CGAL's
/// operators can leave on meshes with many holes and which the other stages cannot take is
/// repaired in `mesh`: faces of zero area are removed (PMP::remove_degenerate_faces), and
/// vertices pinched between two boundary loops or fans are duplicated
/// (PMP::duplicate_non_manifold_vertices). Returns a manifold, consistently oriented mesh.
/// `repairs` (if given) receives the counts.
Mesh from_surface_mesh(SurfaceMesh& mesh, SurfaceRepairs* repairs = nullptr);

}  // namespace vertexflow::remesh_detail
