"""vertexflow.lod and `vertexflow lod` (include/vertexflow/lod.h, docs/lod.md): the same bytes from
Python and the CLI, a resumed run that skips the levels an earlier one finished and ends with the
bytes of an uninterrupted run, --force, and bad levels refused in one line."""

import json
import subprocess

import numpy as np

import vertexflow
from conftest import CLI, DATA

# spot (5,856 faces, closed), with fewer area samples than the default so each run takes about a
# second; the figures still come from the same code as the default's.
SAMPLES = "50000"


def run_lod(*args):
    return subprocess.run([CLI, "lod", *map(str, args), "--samples", SAMPLES], capture_output=True, text=True)


def level_files(out):
    return sorted(p for p in out.iterdir() if p.suffix == ".ply")


def test_python_and_the_cli_give_the_same_bytes(tmp_path):
    result = run_lod(DATA / "spot.obj", tmp_path, "--levels", "30,10,3", "--format", "ply")
    assert result.returncode == 0, result.stderr
    files = level_files(tmp_path)
    assert [p.name for p in files] == ["spot_lod1_1757.ply", "spot_lod2_586.ply", "spot_lod3_176.ply"]
    summary = json.loads((tmp_path / "spot_lod.json").read_text())
    V, F = vertexflow.read_mesh(DATA / "spot.obj")
    levels = vertexflow.lod(V, F, levels=[30, 10, 3], samples=int(SAMPLES))
    assert len(levels) == 3
    faces = [F.shape[0]]
    for path, (Vl, Fl, report), entry in zip(files, levels, summary["levels"]):
        Vc, Fc = vertexflow.read_mesh(path)
        assert Vc.tobytes() == Vl.tobytes()  # PLY keeps float64 exactly
        assert np.array_equal(Fc, Fl)
        assert report["fitted"] == entry["fitted"] and report["qem"] == entry["qem"]
        assert report["faces"] == Fl.shape[0] < faces[-1]  # monotone
        faces.append(Fl.shape[0])
        assert report["flipped_faces"] == 0
        assert report["qem"]["hausdorff"] > 0 and report["fitted"]["hausdorff"] > 0
    md = (tmp_path / "spot_lod.md").read_text()
    assert "| 3 | spot_lod3_176.ply | " in md and "peak memory" in md
    assert summary["peak_memory_bytes"] > 0


def test_a_resumed_run_skips_finished_levels_and_ends_as_an_uninterrupted_one(tmp_path):
    whole, part = tmp_path / "whole", tmp_path / "part"
    assert run_lod(DATA / "spot.obj", whole, "--levels", "30,10,3").returncode == 0
    assert run_lod(DATA / "spot.obj", part, "--levels", "30,10").returncode == 0
    before = {p.name: p.stat().st_mtime_ns for p in part.iterdir()}
    result = run_lod(DATA / "spot.obj", part, "--levels", "30,10,3")
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("finished by an earlier run") == 2
    assert "level 3: simplifying" in result.stderr and "level 1: simplifying" not in result.stderr
    for name in ("spot_lod1_1757.obj", "spot_lod2_586.obj"):
        assert (part / name).stat().st_mtime_ns == before[name]  # not written again
    summary = json.loads((part / "spot_lod.json").read_text())
    assert [level.get("resumed", False) for level in summary["levels"]] == [True, True, False]
    for name in ("spot_lod1_1757.obj", "spot_lod2_586.obj", "spot_lod3_176.obj"):
        assert (part / name).read_bytes() == (whole / name).read_bytes()
    # Other options are another run: nothing is taken from it.
    result = run_lod(DATA / "spot.obj", part, "--levels", "30,10,3", "--edge-flips")
    assert result.returncode == 0 and "earlier run" not in result.stderr
    # --force makes every level anew.
    result = run_lod(DATA / "spot.obj", part, "--levels", "30,10,3", "--force")
    assert result.returncode == 0 and "earlier run" not in result.stderr
    for name in ("spot_lod1_1757.obj", "spot_lod2_586.obj", "spot_lod3_176.obj"):
        assert (part / name).read_bytes() == (whole / name).read_bytes()


def test_bad_levels_are_refused_in_one_line(tmp_path):
    result = run_lod(DATA / "spot.obj", tmp_path, "--levels", "10,30")
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "strictly fewer faces" in lines[0]  # checked before DENSE is read
    result = run_lod(DATA / "spot.obj", tmp_path, "--faces", "6000")
    assert result.returncode == 1 and "not in [1, 5856)" in result.stderr
    assert not list(tmp_path.glob("*.obj"))


def test_a_bad_dense_mesh_leaves_no_directory(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    out = tmp_path / "levels"
    result = run_lod(bad, out)
    assert result.returncode == 1
    errors = [line for line in result.stderr.splitlines() if "error:" in line]
    assert len(errors) == 1 and "bad.obj: face 0 references vertex 2" in errors[0]
    assert not out.exists()  # made for the run, removed when it failed before writing a level
