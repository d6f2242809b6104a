"""Every enhance mode through every front end: the CLI's `enhance`, Python's enhance + write_mesh,
enhance_file and batch (a manifest in the reference modes) write the same bytes."""

import numpy as np
import pytest

import vertexflow
from conftest import DATA, cli_flags, run_cli, sha256, write_manifest

# name: (input, Python keywords, reference, the report's mode). Small meshes, so that the four runs
# of each take seconds; the CLI's flags come from the keywords through the option table.
CASES = {
    "flow": ("sphere_low.off", {"lam": 0.5}, None, "flow"),
    "smooth": ("spot.obj", {"surface": "smooth"}, None, "smooth"),
    "reference-fit": ("bunny_uniform.off", {"max_rounds": 2}, "bunny.off", "reference"),
    "reference-flow": ("bunny_uniform.off", {"reference_method": "flow"}, "bunny.off", "reference-flow"),
    "density-passes": ("spot.obj", {"density_passes": 3}, None, "flow"),
    "edge-flips": ("spot.obj", {"edge_flips": True}, None, "flow"),
    "reference-edge-flips": ("bunny_uniform.off", {"edge_flips": True, "max_rounds": 1, "flip_cycles": 1},
                             "bunny.off", "reference"),
    "unsharp": ("sphere_low.off", {"method": "unsharp", "weight": 0.5}, None, "unsharp"),
}


def test_the_cases_cover_every_mode():
    assert {case[3] for case in CASES.values()} == set(vertexflow.ENHANCE_MODES)


@pytest.mark.parametrize("case", CASES)
def test_cli_python_enhance_file_and_batch_write_the_same_bytes(tmp_path, case):
    name, options, reference_name, mode = CASES[case]
    source = DATA / name
    reference = DATA / reference_name if reference_name else None
    outputs = {path: tmp_path / path / name for path in ("cli", "python", "file", "batch")}
    for output in outputs.values():
        output.parent.mkdir()

    # The CLI.
    run_cli("-q", "enhance", source, outputs["cli"], *cli_flags(options),
            *(["--reference", reference] if reference else []))

    # enhance + write_mesh, with what the CLI reads and writes: the file's face list, its attributes
    # (re-sampled by the engine), and the comments: the input's and the run's line.
    V, F, comments, attributes = vertexflow.read_mesh(source, comments=True, attributes=True, keep_faces=True)
    result = vertexflow.enhance(V, F, reference=reference, provenance=comments, attributes=attributes, threads=1,
                                **options)
    faces_change = options.get(vertexflow._options.FACES_OPTION, False)
    assert len(result) == (4 if faces_change else 3)
    V_out, F_out, attributes_out, report = result if faces_change else (result[0], F, *result[1:])
    assert report["method"] == mode and report["warnings"] == []
    assert V_out.shape == V.shape and F_out.shape == F.shape
    vertexflow.write_mesh(outputs["python"], V_out, F_out, comments=comments + [report["provenance"]],
                          attributes=attributes_out)

    # enhance_file, and batch: its input list, or in a reference mode a manifest row.
    row = vertexflow.enhance_file(source, outputs["file"], reference=reference, **options)
    assert row["status"] == "done" and row["mode"] == mode, row["error"]
    if reference:
        manifest = write_manifest(tmp_path / "manifest.csv", [{"input": source, "reference": reference}])
        summary = vertexflow.batch(output_dir=outputs["batch"].parent, manifest=manifest, **options)
    else:
        summary = vertexflow.batch([source], outputs["batch"].parent, **options)
    assert summary["done"] == 1 and summary["files"][0]["mode"] == mode, summary["files"][0]["error"]

    hashes = {path: sha256(output) for path, output in outputs.items()}
    assert len(set(hashes.values())) == 1, hashes
    if reference is not None:
        # A reference given as arrays: the same vertices; the provenance line names it '?'.
        arrays = vertexflow.enhance(V, F, reference=vertexflow.read_mesh(reference), provenance=comments,
                                    attributes=attributes, **options)
        assert arrays[0].tobytes() == V_out.tobytes()
        assert arrays[-1]["provenance"] == report["provenance"].replace(f" {reference.name} ", " ? ")
    # The flow, the fit and the mask moved vertices; edge flips changed faces.
    assert np.abs(V_out - V).max() > 0
    assert np.array_equal(F_out, F) != faces_change
