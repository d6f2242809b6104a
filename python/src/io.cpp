// Mesh files and the array checks: read_mesh, write_mesh, as_vertices, as_faces (io.h).
#include "convert.h"

#include "vertexflow/io.h"

#include <pybind11/stl/filesystem.h>

namespace vertexflow::python {
namespace {

py::tuple py_read_mesh(const std::filesystem::path& path, bool comments, bool attributes, bool keep_faces) {
  ReadOptions options;
  options.keep_face_list = keep_faces;
  Mesh mesh;
  {
    py::gil_scoped_release release;
    mesh = read_mesh(path, nullptr, options);
  }
  py::list result;
  result.append(to_numpy(std::move(mesh.V)));
  result.append(to_numpy(std::move(mesh.F)));
  if (comments) {
    py::list lines;
    for (const std::string& line : mesh.comments) lines.append(line);
    result.append(lines);
  }
  if (attributes) result.append(attributes_to_python(std::move(mesh.attributes)));
  return py::tuple(result);
}

void py_write_mesh(const std::filesystem::path& path, const py::handle& V, const py::handle& F, bool ascii,
                   const py::object& comments, const py::object& attributes) {
  Mesh mesh = to_mesh(V, F);
  mesh.comments = string_lines(comments, "comments");
  mesh.attributes = attributes_from_python(attributes, mesh.num_vertices(), mesh.num_faces());
  WriteOptions options;
  if (ascii) {
    options.ply_encoding = PlyEncoding::Ascii;
    options.stl_binary = false;
  }
  // What the format cannot hold is named, as the CLI does (one UserWarning), never dropped
  // without a word.
  const std::string lost = attributes_not_written_warning(mesh, format_from_path(path), options);
  if (!lost.empty()) {
    const std::string message = path.string() + ": " + lost;
    if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 1) != 0) throw py::error_already_set();
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
        py::arg("attributes") = false, py::arg("keep_faces") = false,
        R"doc(Reads a mesh (OBJ, PLY, OFF, STL, optionally .gz, and the other formats of io.h) into (V, F):
V (n, 3) float64, F (m, 3) int32. Polygons are triangulated and the mesh cleaned as vertexflow's
reader does (io.h): unreferenced vertices and repeated-index, duplicate and zero-area faces are
removed, unless keep_faces=True, which keeps the file's face list and vertex list (polygons are
still triangulated, in place), as `vertexflow enhance` reads its input.

comments=True adds the file's comment lines, a list of str (PLY `comment`, OBJ and OFF '#' lines;
at most 256, each cut to 1024 bytes), which hold the provenance lines of `vertexflow enhance`
(pass them to enhance(provenance=...)). attributes=True adds the mesh's attributes, a dict
(MeshAttributes: texture coordinates, normals, colours, labels, every PLY property; see
help(vertexflow.MeshAttributes)); a glTF file's document is not part of it (glTF round trips go
through enhance_file, batch or the CLI). The result is (V, F[, comments][, attributes]), in that
order. Raises OSError with "FILE: problem" for any file problem.)doc");
  m.def("write_mesh", &py_write_mesh, py::arg("path"), py::arg("V"), py::arg("F"), py::kw_only(),
        py::arg("ascii") = false, py::arg("comments") = py::none(), py::arg("attributes") = py::none(),
        R"doc(Writes (V, F) atomically (temporary file, then rename); the format follows the extension
(.obj, .ply, .off, .stl, optionally .gz, and the other formats of io.h). PLY keeps float64
coordinates exactly. ascii=True writes ASCII PLY/STL. comments, a sequence of str, are written as
comment lines (PLY, OBJ, ASCII OFF; STL and binary OFF have none). attributes, a dict as
read_mesh(attributes=True) returns it (MeshAttributes), is written with its channels' names,
types and order where the format holds them (PLY every vertex and face channel and one texture
coordinate per corner, OBJ texture coordinates, normals, materials, groups, objects; io.h's
attributes_not_written); what the format cannot hold is left out, named in one UserWarning. A glTF output is written as
one primitive: the input document is not carried (enhance_file and batch carry it). Raises
ValueError for bad arrays or attributes (naming the key), OSError for file problems.)doc");
}

}  // namespace vertexflow::python
