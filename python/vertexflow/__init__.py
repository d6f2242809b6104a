# The package vertexflow: the compiled module vertexflow._core (python/src/), re-exported, and the
# functions that take the enhance options (enhance, enhance_file, batch, enhance_options), whose
# keywords, defaults and docstrings come from the library's option table (_options.py).
# Imported under private names: the package's namespace is its API (and the stub's).
import inspect as _inspect
import os as _os
from typing import Any as _Any, Callable as _Callable, Iterable as _Iterable, Literal as _Literal
from typing import NotRequired as _NotRequired, Sequence as _Sequence, TypedDict as _TypedDict

import numpy as _np

from . import _core
from ._core import *  # noqa: F401,F403  read_mesh, write_mesh, compare, render, ... (python/src/*.cpp)
from ._core import __version__, _time_vertex_flow  # noqa: F401
from ._options import ENHANCE_MODES, ENHANCE_OPTIONS, EnhanceOption  # noqa: F401
from ._options import front_end as _front_end

__doc__ = _core.__doc__

_Path = str | _os.PathLike


class AttributeChannel(_TypedDict):
    """One channel of a mesh's attributes (include/vertexflow/attributes.h), as read_mesh(...,
    attributes=True) and enhance(..., attributes=...) return it and write_mesh and enhance take it.

    name: "uv", "normal", "color", "material", or a PLY property's own name.
    components: the file's component names, in file order (["s", "t"], ["red", "green", "blue"]).
      May be left out for a one-column channel (then [name]).
    type: the scalar type the file has and a writer writes: "int8", "uint8", "int16", "uint16",
      "int32", "uint32", "float32" or "float64" (default). Integer types' values must be integers
      in the type's range.
    role: how the channel follows a moved vertex in enhance: "generic" (default; interpolated),
      "color" (interpolated, rounded), "texcoord" (interpolated in the vertex's own chart; seams
      are creases), "normal" (recomputed), "label" (kept), "weights" (interpolated, renormalised).
    values: (rows, len(components)) float64 array (a 1-D array is one column); every type's values
      are exact in float64. Rows are the mesh's vertices (a vertex channel), faces (a face
      channel), or the channel's own table of values (a corner channel).
    """

    name: str
    components: _NotRequired[list[str]]
    type: _NotRequired[str]
    role: _NotRequired[str]
    values: _np.ndarray


class CornerChannel(AttributeChannel):
    """A channel whose values belong to face corners (OBJ `vt`/`vn` with their own indices, PLY face
    `texcoord` lists): corners, an (m, 3) int32 array with one row per face, holds the row of values
    each corner uses, -1 where the corner has none. A seam is where a vertex's corners use
    different rows."""

    corners: _np.ndarray


class MeshAttributes(_TypedDict, total=False):
    """What a mesh carries besides V and F (include/vertexflow/attributes.h, docs/attributes.md):
    read_mesh(path, attributes=True) returns it with every key; write_mesh, enhance take it, with
    missing keys as empty lists. Bad dicts raise ValueError naming the key.

    vertex: channels with one row per vertex (PLY vertex properties after x y z, colours).
    corner: CornerChannels (texture coordinates and normals per face corner).
    face: channels with one row per face (PLY face properties; OBJ "material", "group",
      "object" labels, int32 indices into the name tables below, -1 for none, and "smoothing").
    materials, groups, objects: the names the OBJ labels index, in first-use order.
    material_libraries: OBJ `mtllib` file names, in file order.

    A glTF file's document (materials, textures, nodes, ...) is not part of the dict: a mesh read
    from glTF and written from Python is written as one primitive. enhance_file, batch and the
    CLI carry the document through.
    """

    vertex: list[AttributeChannel]
    corner: list[CornerChannel]
    face: list[AttributeChannel]
    materials: list[str]
    groups: list[str]
    objects: list[str]
    material_libraries: list[str]



def _positional(name, default=_inspect.Parameter.empty, annotation=_inspect.Parameter.empty):
    return _inspect.Parameter(name, _inspect.Parameter.POSITIONAL_OR_KEYWORD, default=default, annotation=annotation)


def _keyword(name, default, annotation=_inspect.Parameter.empty):
    return _inspect.Parameter(name, _inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation)


enhance = _front_end(
    "enhance",
    [_positional("V"), _positional("F"),
     _keyword("reference", None, tuple | _Path | None),
     _keyword("provenance", None, _Sequence[str] | None),
     _keyword("attributes", None, MeshAttributes | None),
     _keyword("threads", 0, int),
     _keyword("progress", None, _Callable[[str], _Any] | None)],
    lambda options, V, F, reference, provenance, attributes, threads, progress: _core._enhance(
        V, F, options, reference, provenance, attributes, threads, progress),
    """
Enhances the mesh (V, F) with the engine of `vertexflow enhance` (enhance.h), in any of its modes,
then flips edges if asked.

Returns (V_out, report). V_out, (n, 3) float64, is bit for bit what `vertexflow enhance` writes for
the same options. report is the engine's report as a dict: "method" (the mode), "options", what
the method measured (solver, guard, fit, ...), "seconds", "provenance" (the line the CLI appends
to the output's comments: write_mesh(path, V_out, F, comments=provenance + [report["provenance"]])
writes the CLI's bytes for an input without attributes) and "warnings". The one option that
changes the faces (edge flips) makes it return (V_out, F_out, report); otherwise the faces are F's.

With attributes (a MeshAttributes dict, as read_mesh(path, attributes=True) returns), the engine
gets them as the CLI gets its input's: texture seams and material and other label boundaries are
creases, and each moved vertex's channels are re-sampled where it lands. The result then also
holds the re-sampled attributes, before the report: (V_out, attributes_out, report), or
(V_out, F_out, attributes_out, report) with edge flips; report["attributes"] says how many were
re-sampled and how far. The CLI's bytes, for any input:

    V, F, comments, attributes = read_mesh(path, comments=True, attributes=True, keep_faces=True)
    V_out, attributes_out, report = enhance(V, F, provenance=comments, attributes=attributes)
    write_mesh(out, V_out, F, comments=comments + [report["provenance"]], attributes=attributes_out)

(keep_faces=True reads the face list as `vertexflow enhance` does; enhance_file does all of it.)

reference: the dense mesh of the true surface, for the reference modes: a pair (V_ref, F_ref), or
  a mesh file's path, read as `--reference` reads it (its file name goes into the provenance
  line; a pair is named '?').
provenance: the input's comment lines (read_mesh(path, comments=True)). Smooth mode holds an input
  whose provenance records an earlier fit, which placed it off its surface, as the CLI does
  (report["fit"]["held_as_fitted"], ["fitted_by"]).
attributes: the input's attributes (MeshAttributes) or None; see above. ValueError naming the key
  of a bad dict (or the channel whose rows do not match V or F).
threads: TBB threads, 0 for all cores; the result does not depend on it.
progress: progress(str) is called before and after the work.

The options are those of the library's table, which the CLI's flags also come from. An option
set to other than its default in a mode it does not apply to raises ValueError naming it, as the
CLI refuses it; so does a value out of its range.

Before the run, its peak memory is estimated from the vertex count (vertexflow/memory.h): a run
that would not fit raises MemoryError with one line; where only the default solver's multilevel
preconditioner would not fit, the flow runs block-Jacobi alone and report["warnings"] says so.
""")

enhance_file = _front_end(
    "enhance_file",
    [_positional("input", annotation=_Path), _positional("output", annotation=_Path),
     _keyword("reference", None, _Path | None),
     _keyword("force", False, bool),
     _keyword("metrics", True, bool),
     _keyword("threads", 0, int)],
    lambda options, input, output, reference, force, metrics, threads: _core._enhance_file(
        input, output, options, reference, force, metrics, threads),
    """
One file of `vertexflow batch`, in any mode: reads input (and reference, a mesh file's path, for
the reference modes), enhances it, writes output atomically (the bytes `vertexflow enhance input
output [--reference reference]` writes for the same options) and measures it -> the summary row
as a dict (input, output, reference, mode, status, error, warnings, vertices, faces, seconds and
the metrics).

Never raises for a problem of the file: the row's status is "done", "skipped" (output exists and
not force) or "failed" with its "error". Options that do not apply to the mode or are out of range
raise ValueError before anything is read.

force: overwrite an existing output.
metrics: measure rho, edge-error CV, flipped faces, displacement and, with a reference, the
  distances of input and result to it.
threads: TBB threads for this file, 0 for all cores.
""")

batch = _front_end(
    "batch",
    [_positional("inputs", None, _Path | _Iterable[_Path] | None),
     _positional("output_dir", None, _Path | None),
     _keyword("manifest", None, _Path | None),
     _keyword("reference_dir", None, _Path | None),
     _keyword("jobs", 1, int),
     _keyword("threads", 0, int),
     _keyword("force", False, bool),
     _keyword("metrics", True, bool),
     _keyword("progress", None, _Callable[[dict], _Any] | None)],
    lambda options, inputs, output_dir, manifest, reference_dir, jobs, threads, force, metrics, progress: _core._batch(
        inputs, output_dir, options, manifest, reference_dir, jobs, threads, force, metrics, progress),
    """
`vertexflow batch`: enhance_file over many files, in any mode, jobs files at once (threads TBB
threads each; 0: the cores divided among the jobs). output_dir is required.

The files: inputs, a directory (its mesh files), a glob pattern, a file or a list of them, each
written to output_dir under its file name; or manifest, a CSV (header input,reference,output) or
JSON (a list of {input, reference, output}) file as `vertexflow batch --manifest` reads it
(read_batch_manifest): a row's reference runs a reference mode, its output (optional) names the
output. reference_dir: each input's reference is the mesh of this directory with the input's
stem. In a reference mode, a file without a reference fails (its error, not the batch's).

Failing files are reported and skipped; existing outputs are skipped unless force. Writes
output_dir/batch_summary.csv and .json; returns {"files": [rows as enhance_file's], "done",
"skipped", "failed", "seconds", "csv", "json"}. progress(dict) is called after each file
(finished, total, failed, input, status, error, elapsed, eta); an exception it raises
(KeyboardInterrupt included; Ctrl-C does the same) stops the batch at the next file boundary, keeps the files
written and the summary of those finished, and is raised again. An unreadable earlier summary in
output_dir is named in a UserWarning, and the skipped files are measured again from their outputs.
""")

enhance_options = _front_end(
    "enhance_options",
    [_keyword("has_reference", False, bool), _keyword("naming", "python", _Literal["python", "cli"])],
    lambda options, has_reference, naming: _core._enhance_options(options, has_reference, naming),
    """
Checks the options as enhance does for a run with or without a reference (ValueError naming an
option that does not apply to the mode, or a value out of range) -> every option's value by
keyword, as batch summaries record them (pins as their count). naming="cli" names the options in
the errors as the CLI's flags (for front ends that take those, as examples/dask_batch.py).
""")
