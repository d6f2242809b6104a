"""vertexflow.remesh on a raw-scan-like mesh (issue 31, docs/remesh.md): the CLI's options for raw
scans as keywords (small_pieces, small_piece_edges, short_loop_edges, fill_holes_below), their
range checks, report=True giving what `vertexflow remesh --json` prints (one builder,
remesh_report_json.h), and the same report numbers and output bytes from Python and the CLI."""

import json

import numpy as np
import pytest

import vertexflow
from conftest import DATA, run_cli

TARGET = 800
# Three closed tetrahedra 0.02 across, floating above the hemisphere (radius 1, its rim at z = 0.1):
# far below the target edge of about 0.1, so too small to remesh.
PIECE_CENTRES = [(0.0, 0.0, 2.0), (0.5, 0.5, 1.8), (-0.5, 0.3, 1.9)]
PIECE_FACES = 3 * 4


def raw_scan():
    """hemisphere.off (one boundary loop) with one face cut out near its top (a hole far shorter
    than three target edges) and three tiny floating pieces."""
    V, F = vertexflow.read_mesh(DATA / "hemisphere.off")
    centroids = V[F].mean(axis=1)
    F = np.delete(F, np.argmax(centroids[:, 2]), axis=0)
    corners = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=np.float64) * 0.01
    tetrahedron = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    Vs, Fs = [V], [F]
    for i, centre in enumerate(PIECE_CENTRES):
        Vs.append(corners + np.array(centre))
        Fs.append(tetrahedron + len(V) + 4 * i)
    return np.vstack(Vs), np.vstack(Fs).astype(np.int32)


@pytest.fixture(scope="module")
def scan():
    return raw_scan()


def without_times(report):
    """The report but its seconds (wall times differ from run to run)."""
    report = {k: v for k, v in report.items() if k != "seconds"}
    report["runs"] = [{k: v for k, v in run.items() if k != "seconds"} for run in report["runs"]]
    return report


def test_default_return_is_still_a_pair(scan):
    result = vertexflow.remesh(*scan, target_vertices=TARGET)
    assert len(result) == 2
    V, F, _ = vertexflow.remesh(*scan, target_vertices=TARGET, report=True)
    assert np.array_equal(result[0], V) and np.array_equal(result[1], F)


def test_small_pieces_are_removed_by_default_and_counted(scan):
    V, F, report = vertexflow.remesh(*scan, target_vertices=TARGET, report=True)
    assert report["cleanup"]["small_pieces"] == len(PIECE_CENTRES)
    assert report["cleanup"]["small_piece_faces"] == PIECE_FACES
    assert report["cleanup"]["small_pieces_kept"] is False
    assert report["components"] == 1
    assert report["small_piece_edges"] == 2.0
    # No output vertex is near a piece.
    for centre in PIECE_CENTRES:
        assert np.linalg.norm(V - np.array(centre), axis=1).min() > 0.5
    assert report["vertices"] == len(V) and report["faces"] == len(F)
    assert report["input_vertices"] == len(scan[0])


def test_small_pieces_keep_copies_them_unchanged(scan):
    V, F, report = vertexflow.remesh(*scan, target_vertices=TARGET, small_pieces="keep", report=True)
    assert report["cleanup"]["small_pieces"] == len(PIECE_CENTRES)
    assert report["cleanup"]["small_pieces_kept"] is True
    assert report["components"] == 1 + len(PIECE_CENTRES)
    # Each tetrahedron's four corners are in the output exactly.
    for i in range(len(PIECE_CENTRES)):
        start = len(scan[0]) - 4 * (len(PIECE_CENTRES) - i)
        for corner in scan[0][start : start + 4]:
            assert (V == corner).all(axis=1).any()
    # small_piece_edges=0 remeshes every piece: none is taken out.
    _, _, report0 = vertexflow.remesh(*scan, target_vertices=TARGET, small_piece_edges=0, report=True)
    assert report0["cleanup"]["small_pieces"] == 0 and report0["small_piece_edges"] == 0


def test_short_loops_are_kept_or_filled(scan):
    _, _, kept = vertexflow.remesh(*scan, target_vertices=TARGET, report=True)
    assert kept["cleanup"]["short_loops_kept"] == 1 and kept["cleanup"]["held_loop_vertices"] >= 3
    assert kept["boundary_loops"] == 2
    _, _, free = vertexflow.remesh(*scan, target_vertices=TARGET, short_loop_edges=0, report=True)
    assert free["cleanup"]["short_loops_kept"] == 0
    _, _, filled = vertexflow.remesh(*scan, target_vertices=TARGET, fill_holes_below=3, report=True)
    assert filled["cleanup"]["filled_holes"] == 1 and filled["boundary_loops"] == 1
    assert filled["fill_hole_edges"] == 3


def test_report_has_interior_and_rim_quality(scan):
    _, F, report = vertexflow.remesh(*scan, target_vertices=TARGET, report=True)
    assert report["interior_faces"] > 0 and report["rim_faces"] > 0
    assert report["interior_faces"] + report["rim_faces"] == len(F)
    for key in ("quality", "quality_interior", "quality_rim"):
        assert 0 <= report[key]["fraction_below_0_3"] <= 1
        assert 0 < report[key]["min"] <= report[key]["mean"] <= 1
    assert report["within_tolerance"] is True and report["target_vertices"] == TARGET
    assert set(report["repairs"]) == {"input_split_vertices", "input_reoriented_faces", "input_cut_edges",
                                      "removed_degenerate_faces", "duplicated_vertices"}


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(small_pieces="drop"), "small_pieces: 'drop' is not one of keep, remove"),
        (dict(small_piece_edges=-1), "small_piece_edges: -1.0 is not in the allowed range ([0, 1000])"),
        (dict(small_piece_edges=1001), "small_piece_edges: 1001.0 is not in the allowed range ([0, 1000])"),
        (dict(short_loop_edges=2000), "short_loop_edges: 2000.0 is not in the allowed range ([0, 1000])"),
        (dict(fill_holes_below=float("nan")), "fill_holes_below: nan is not in the allowed range ([0, 1000])"),
    ],
)
def test_bad_values_raise_value_error(scan, kwargs, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
        vertexflow.remesh(*scan, target_vertices=TARGET, **kwargs)


def test_cli_refuses_what_python_refuses(scan, tmp_path):
    source = tmp_path / "scan.ply"
    vertexflow.write_mesh(source, *scan)
    result = run_cli("remesh", source, tmp_path / "out.ply", "--target-vertices", TARGET, "--small-piece-edges", 1001,
                     check=False)
    assert result.returncode != 0
    assert "--small-piece-edges: 1001 is not in the allowed range ([0, 1000])" in result.stderr


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        ([], {}),
        (["--small-pieces", "keep", "--short-loop-edges", "0"], dict(small_pieces="keep", short_loop_edges=0)),
        (["--fill-holes-below", "2.5", "--small-piece-edges", "3", "--protect-boundary", "--iterations", "5"],
         dict(fill_holes_below=2.5, small_piece_edges=3, protect_boundary=True, iterations=5)),
    ],
)
def test_python_and_the_cli_give_the_same_report_and_bytes(scan, tmp_path, flags, kwargs):
    source = tmp_path / "scan.ply"
    vertexflow.write_mesh(source, *scan)
    cli_out = tmp_path / "cli.ply"
    result = run_cli("--quiet", "remesh", source, cli_out, "--target-vertices", TARGET, "--json", *flags)
    cli_report = json.loads(result.stdout)
    assert cli_report.pop("input") == str(source) and cli_report.pop("output") == str(cli_out)

    V, F = vertexflow.read_mesh(source)  # what the CLI read
    Vr, Fr, report = vertexflow.remesh(V, F, target_vertices=TARGET, report=True, **kwargs)
    assert set(report) == set(cli_report)
    assert without_times(report) == without_times(cli_report)
    python_out = tmp_path / "python.ply"
    vertexflow.write_mesh(python_out, Vr, Fr)
    assert python_out.read_bytes() == cli_out.read_bytes()
