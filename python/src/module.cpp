// The compiled part of the Python package vertexflow: vertexflow._core, one register_* per topic
// (convert.h). The package (python/vertexflow/__init__.py) re-exports it and adds enhance,
// enhance_file and batch, whose signatures come from the option table.
#include "convert.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = R"doc(vertexflow: feature enhancement of triangle meshes by vertex flow (Ji et al. 2011).

Meshes are numpy arrays, libigl-style: V is (n, 3) float64 (other dtypes and orders are converted;
C-contiguous float64 is used as it is), F is (m, 3) integer vertex indices. What a mesh carries
besides (texture coordinates, normals, colours, labels, PLY properties) is a dict, MeshAttributes:
read_mesh(path, attributes=True) returns it, write_mesh and enhance take it. Bad arrays and options
raise ValueError, file problems OSError, each with the library's message. Heavy calls release the
GIL and take threads=0 (all cores) or a thread count; results do not depend on it. Nothing is
printed: pass progress=callable to hear about progress.)doc";
  m.attr("__version__") = "0.1.0";
  vertexflow::python::register_exception_translators();
  vertexflow::python::register_io(m);
  vertexflow::python::register_enhance(m);
  vertexflow::python::register_metrics(m);
  vertexflow::python::register_remesh(m);
  vertexflow::python::register_render_lines(m);
  vertexflow::python::register_batch(m);
  vertexflow::python::register_lod(m);
}
