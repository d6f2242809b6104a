// Analytic test surfaces, triangulated: sphere, cylinder, torus and a saddle patch, with their
// exact curvatures known in closed form.
#pragma once

#include "vertexflow/mesh.h"

#include <functional>

namespace vertexflow::test {

/// Icosahedron subdivided `levels` times (each triangle into 4), projected onto the sphere of
/// radius R centred at the origin; outward orientation. 10 * 4^levels + 2 vertices.
Mesh icosphere(double radius, int levels);

/// Open cylinder of radius R around the z axis, z in [0, height], `around` x `along` quads
/// split into triangles (alternating diagonals); outward orientation.
Mesh cylinder(double radius, double height, int around, int along);

/// Torus around the z axis: tube centre radius R, tube radius r; `around` segments along the
/// big circle, `tube` around the tube; vertex (i, j) is at angles (2 pi i / around,
/// 2 pi j / tube) with theta = 0 on the outer equator; outward orientation.
Mesh torus(double R, double r, int around, int tube);

/// The torus with an elliptic tube: semi-axis `a` in the radial direction, `b` along z; vertex
/// (i, j) at (R + a cos theta) (cos phi, sin phi) + b sin theta z. With a > b the meridian
/// curvature a / b^2 at both equators is the maximum over the tube; outward orientation.
Mesh elliptic_torus(double R, double a, double b, int around, int tube);

/// The graph z = height(x, y) over [-half, half]^2, n x n quads; normals up (+z).
Mesh height_field(double half, int n, const std::function<double(double, double)>& height);

/// A cube with rounded edges and corners: the points within `radius` of the cube [-core, core]^3
/// (flat faces at +-(core + radius), quarter-cylinders along the edges, eighth-spheres at the
/// corners), from an n x n grid per face; closed, outward orientation.
Mesh rounded_cube(double core, double radius, int n);

/// The saddle z = (x^2 - y^2) / 2 over [-half, half]^2, n x n quads; normals up (+z).
Mesh saddle(double half, int n);

/// An n x n grid over [0, 1]^2 lifted to the roof z = -|x - y| / 2, whose ridge runs along the
/// diagonal x = y through the vertices (i, i). Each square is split by the diagonal from
/// (i + 1, j) to (i, j + 1) when `across`: the squares on the ridge are then cut across it, and
/// their faces sag below the roof; otherwise by the diagonal from (i, j) to (i + 1, j + 1),
/// which follows the ridge. Normals up (+z).
Mesh roof(int n, bool across);

/// Two triangles sharing only vertex 0 (a "bowtie"): the smallest non-manifold mesh.
Mesh bowtie();

/// `mesh` renumbered at random (std::mt19937 with `seed`): vertex v becomes new_index[v], the
/// faces come in a shuffled order, and with `rotate_corners` face f of the result lists its
/// corners rotated by f % 3 (the same orientation). The same surface, for order invariance.
struct Renumbered {
  Mesh mesh;
  std::vector<Index> new_index;
};
Renumbered renumbered(const Mesh& mesh, unsigned seed, bool rotate_corners);

/// A thin perforated plate, a hard case for the flow (thin walls, sharp creases, high genus):
/// (2 holes + 1)^2 unit cells in the xy-plane, every cell with odd row and column a square
/// through-hole, `thickness` thick in z, each cell cut into `subdivisions`^2 quads (two
/// triangles each). With `bottom` the solid is closed with genus holes^2; without it the
/// bottom face is left open, so each hole and the outer rim end in a boundary loop (a
/// sheet-metal-like CAD part). Outward orientation.
Mesh perforated_plate(int holes, int subdivisions, double thickness, bool bottom);

/// A sliver-heavy thin shape of high genus: perforated_plate(holes, ..., thickness, bottom) with
/// each unit cell cut into `slivers` strips along x (two triangles each, one cell long in y),
/// and every vertex off the cells' lines x = integer moved along x by up to `jitter` strip
/// widths (uniform, fixed seed), so that the slivers differ. With 8 strips about 75% of the
/// faces start below radius ratio 0.3.
Mesh sliver_plate(int holes, int slivers, double thickness, double jitter, unsigned seed);

/// `mesh` with `count` faces chosen uniformly at random (fixed seed) removed, vertices kept:
/// a scan with many small holes. Holes that touch at a vertex make it non-manifold, as in
/// real scans.
Mesh with_random_faces_removed(const Mesh& mesh, Index count, unsigned seed);

/// Vertex-clustering decimation of `mesh` (Rossignac and Borrel 1993), the way the Stanford
/// repository's low-resolution scans were made: vertices are merged per cube of a grid of
/// `cell` edge length (at the mean of the cube's vertices), faces with two corners in one cube
/// are dropped, repeated faces kept once. Like those scans the result has non-manifold edges
/// and vertices.
Mesh vertex_clustered(const Mesh& mesh, double cell);

/// A simulated noisy scan of `mesh`: every vertex displaced along its normal by Gaussian noise
/// of `normal_noise` mean edge lengths and in the tangent plane by up to `tangential_jitter`
/// mean edge lengths (uniform), which turns many triangles into slivers; fixed seed.
Mesh noisy_scan(const Mesh& mesh, double normal_noise, double tangential_jitter, unsigned seed);

}  // namespace vertexflow::test
