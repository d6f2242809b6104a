// Conversion between vertexflow's V/F matrices and CGAL::Surface_mesh, shared by the stages that
// run CGAL halfedge algorithms (simplify.cpp, remesh.cpp). Not installed: CGAL types stay out of
// the public headers.
#pragma once

#include "vertexflow/mesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <string>

namespace vertexflow::remesh_detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

/// A Surface_mesh with the vertices of V (same order, including unreferenced ones) and the
/// faces of F (same order and orientation). `stage` prefixes the error messages ("simplify").
/// Throws std::invalid_argument for an empty mesh, an index out of range, a non-manifold mesh
/// (describe_non_manifold) or faces that are not consistently oriented: a halfedge mesh cannot
/// represent those, and these stages refuse them rather than process part of the surface.
SurfaceMesh to_surface_mesh(const Vertices& V, const Faces& F, const std::string& stage);

/// V/F of `mesh`: removed elements (garbage) and vertices without faces are skipped, the others
/// keep their relative order and the faces their orientation.
Mesh from_surface_mesh(const SurfaceMesh& mesh);

}  // namespace vertexflow::remesh_detail
