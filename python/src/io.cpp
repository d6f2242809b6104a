// Mesh files and the array checks: read_mesh, write_mesh, as_vertices, as_faces (io.h).
#include "convert.h"

#include "vertexflow/io.h"

#include <pybind11/stl/filesystem.h>

namespace vertexflow::python {
namespace {

py::tuple py_read_mesh(const std::filesystem::path& path, bool comments) {
  Mesh mesh;
  {
    py::gil_scoped_release release;
    mesh = read_mesh(path);
  }
  if (!comments) return mesh_tuple(std::move(mesh));
  py::list lines;
  for (const std::string& line : mesh.comments) lines.append(line);
  const py::tuple pair = mesh_tuple(std::move(mesh));
  return py::make_tuple(pair[0], pair[1], lines);
}

void py_write_mesh(const std::filesystem::path& path, const py::handle& V, const py::handle& F, bool ascii,
                   const py::object& comments) {
  Mesh mesh = to_mesh(V, F);
  mesh.comments = string_lines(comments, "comments");
  WriteOptions options;
  if (ascii) {
    options.ply_encoding = PlyEncoding::Ascii;
    options.stl_binary = false;
  }
  py::gil_scoped_release release;
  write_mesh(path, mesh, options);
}

}  // namespace

void register_io(py::module_& m) {
  m.def(
      "as_vertices", [](const py::handle& V) { return as_vertices(V); }, py::arg("V"),
      R"doc(V as the module uses it: a C-contiguous float64 (n, 3) array, n > 0, finite. Returns V itself
when it is one already (no copy), else a converted copy. Raises ValueError otherwise.)doc");
  m.def(
      "as_faces", [](const py::handle& F, py::ssize_t n) { return as_faces(F, n); }, py::arg("F"),
      py::arg("num_vertices"),
      R"doc(F as the module uses it: a C-contiguous int64 (m, 3) array, m > 0, every index in
[0, num_vertices). Returns F itself when it is one already. Raises ValueError otherwise.)doc");
  m.def("read_mesh", &py_read_mesh, py::arg("path"), py::kw_only(), py::arg("comments") = false,
        R"doc(Reads a mesh (OBJ, PLY, OFF, STL, optionally .gz) into (V, F): V (n, 3) float64, F (m, 3) int32.
Polygons are triangulated and the mesh cleaned as vertexflow's reader does (io.h). comments=True
returns (V, F, comments): the file's comment lines as a list of str (PLY `comment`, OBJ and OFF
'#' lines; at most 256, each cut to 1024 bytes), which hold the provenance lines of
`vertexflow enhance` (pass them to enhance(provenance=...)). Raises OSError with "FILE: problem"
for any file problem.)doc");
  m.def("write_mesh", &py_write_mesh, py::arg("path"), py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("ascii") = false, py::arg("comments") = py::none(),
        R"doc(Writes (V, F) atomically (temporary file, then rename); the format follows the extension
(.obj, .ply, .off, .stl, optionally .gz). PLY keeps float64 coordinates exactly. ascii=True writes
ASCII PLY/STL. comments, a sequence of str, are written as comment lines (PLY, OBJ, ASCII OFF;
STL and binary OFF have none). Raises ValueError for bad arrays, OSError for file problems.)doc");
}

}  // namespace vertexflow::python
