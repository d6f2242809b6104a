"""`vertexflow batch` and vertexflow.batch(): 20 data meshes, a corrupt file and a non-mesh file (not
listed: a directory gives its mesh files); failures reported and skipped, outputs as `vertexflow enhance` writes them, resumable. Reference
mode over a manifest of (coarse, dense) pairs: the bytes of `vertexflow enhance --reference`."""

import csv
import json
import os
import shutil

import numpy as np
import pytest

import vertexflow
from conftest import DATA, cli_reference_outputs, run_cli, sha256, write_manifest


@pytest.fixture(scope="module")
def messy(dataset20, tmp_path_factory):
    """The 20 meshes, a truncated OFF file and a text file."""
    directory = tmp_path_factory.mktemp("messy")
    for path in dataset20.iterdir():
        shutil.copy(path, directory / path.name)
    (directory / "corrupt.off").write_text("OFF\n100 50 0\n0 0 0\n1 0 0\n")
    (directory / "notes.txt").write_text("not a mesh\n")
    return directory


@pytest.fixture(scope="module")
def cli_run(messy, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli_batch")
    first = run_cli("batch", messy, out, "--jobs", "2", "--threads", "1", check=False)
    return out, first


def read_summary(out):
    with open(out / "batch_summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return rows, json.loads((out / "batch_summary.json").read_text())


def test_batch_completes_and_reports_both_failures(cli_run):
    out, first = cli_run
    assert first.returncode == 1  # some files failed, after all of them were tried
    assert "1 of 21 files failed" in first.stderr
    rows, summary = read_summary(out)
    assert len(rows) == 21 and len(summary["files"]) == 21
    status = {r["input"].rsplit("/", 1)[1]: r for r in rows}
    assert status["corrupt.off"]["status"] == "failed" and "corrupt.off" in status["corrupt.off"]["error"]
    assert "notes.txt" not in status  # not a mesh file name
    done = [r for r in rows if r["status"] == "done"]
    assert len(done) == 20 and summary["done"] == 20 and summary["failed"] == 1
    for r in done:
        assert r["error"] == ""
        assert int(r["flipped_faces"]) == 0
        assert float(r["seconds_total"]) > 0
        for column in ("rho_input", "rho_result", "cv_input", "cv_result", "displacement_mean"):
            float(r[column])  # measured, not empty
    # The flow moved the vertices of every mesh but those it holds (input_check.h): the decimated
    # scans camelhead and max-planck-5k, and the meshes coarse enough to be subdivision control
    # meshes (suzanne, fandisk_quads, the chamfered cube, the icosahedron).
    still = {r["input"].rsplit("/", 1)[1] for r in done if float(r["displacement_mean"]) == 0}
    assert still == {"chamfer-cube.off", "icosahedron_ascii.stl", "icosahedron_binary.stl", "camelhead.off",
                     "max-planck-5k.obj", "suzanne.obj", "fandisk_quads.off"}
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith("batch_summary")) == sorted(
        r["input"].rsplit("/", 1)[1] for r in done)


def test_batch_outputs_are_what_enhance_writes(cli_run, messy, tmp_path):
    out, _ = cli_run
    for name in ["bunny_uniform.off", "torus_copy.off.gz", "icosahedron_binary.stl", "fandisk_quads.off"]:
        run_cli("-q", "enhance", messy / name, tmp_path / name)
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes()


def test_second_run_skips_everything_done(cli_run, messy):
    out, _ = cli_run
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    first_rows, _ = read_summary(out)
    second = run_cli("batch", messy, out, "--jobs", "2", check=False)
    rows, summary = read_summary(out)
    assert summary["skipped"] == 20 and summary["done"] == 0 and summary["failed"] == 1
    # The skipped files keep the first run's measurements: the table still describes every output.
    for old, new in zip(first_rows, rows):
        assert old["input"] == new["input"]
        if old["status"] == "done":
            assert new["status"] == "skipped"
            for column in ("vertices", "flipped_faces", "rho_input", "rho_result", "cv_result", "displacement_max"):
                assert new[column] == old[column] != "", column
    after = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    assert all(after[n] == before[n] for n in before if not n.startswith("batch_summary"))
    assert second.returncode == 1


def test_python_batch_gives_the_same_bytes(cli_run, messy, tmp_path):
    out, _ = cli_run
    calls = []
    result = vertexflow.batch(messy, tmp_path / "py", jobs=1, threads=1, progress=calls.append)
    assert result["done"] == 20 and result["failed"] == 1 and len(result["files"]) == 21
    assert len(calls) == 21 and calls[-1]["finished"] == 21 and calls[-1]["total"] == 21
    for row in result["files"]:
        if row["status"] == "done":
            name = row["input"].rsplit("/", 1)[1]
            assert (tmp_path / "py" / name).read_bytes() == (out / name).read_bytes()
    again = vertexflow.batch(str(messy / "*.obj"), tmp_path / "py", force=True, metrics=False)
    assert again["done"] == 5 and again["skipped"] == 0  # force redoes them; the glob picks the OBJ files
    assert all(r["redistribution_rho"]["result"] is None for r in again["files"])


def test_enhance_file_reports_failures_without_raising(messy, tmp_path):
    row = vertexflow.enhance_file(messy / "corrupt.off", tmp_path / "corrupt.off")
    assert row["status"] == "failed" and "corrupt.off" in row["error"]
    assert not (tmp_path / "corrupt.off").exists()
    row = vertexflow.enhance_file(messy / "notes.txt", tmp_path / "notes.txt")
    assert row["status"] == "failed" and "notes.txt" in row["error"]
    row = vertexflow.enhance_file(messy / "spot.obj", messy / "spot.obj")
    assert row["status"] == "failed"  # never overwrites its input
    row = vertexflow.enhance_file(DATA / "spot.obj", tmp_path / "spot.obj", lam=0.5)
    assert row["status"] == "done"
    # What enhance_file wrote is what enhance makes of the mesh as the CLI reads it: its face list and
    # its attributes (spot's texture seams are creases), re-sampled in the result.
    V, F, attributes = vertexflow.read_mesh(DATA / "spot.obj", attributes=True, keep_faces=True)
    V_out, attributes_out, _ = vertexflow.enhance(V, F, lam=0.5, attributes=attributes)
    V_file, F_file, attributes_file = vertexflow.read_mesh(tmp_path / "spot.obj", attributes=True, keep_faces=True)
    assert np.array_equal(V_file, V_out)  # OBJ writes 17 significant digits: exact
    assert np.array_equal(F_file, F)
    uv_out, uv_file = attributes_out["corner"][0], attributes_file["corner"][0]
    assert uv_out["name"] == uv_file["name"] == "uv"
    assert np.array_equal(uv_file["values"], uv_out["values"]) and np.array_equal(uv_file["corners"], uv_out["corners"])


# --- reference mode over (coarse, dense) pairs: the level-of-detail pipeline -----------------------


@pytest.fixture(scope="module")
def lod_cli(lod_pairs, tmp_path_factory):
    """`vertexflow enhance COARSE OUT --reference DENSE` per pair: {file name: sha256}."""
    return cli_reference_outputs(lod_pairs, tmp_path_factory.mktemp("lod_cli"))


def test_batch_over_a_manifest_of_pairs_writes_what_enhance_reference_writes(lod_pairs, lod_cli, tmp_path):
    assert len(lod_pairs) >= 4
    coarse_dir = lod_pairs[0][0].parent
    # Inputs relative to the manifest's directory, references absolute; one row names its output.
    rows = [{"input": os.path.relpath(c, tmp_path), "reference": d} for c, d in lod_pairs]
    rows[0]["output"] = "named/" + lod_pairs[0][0].name
    # A row without a reference and one whose reference is missing: their own errors, not the batch's.
    rows += [{"input": DATA / "spot.obj"}, {"input": DATA / "torus.obj", "reference": tmp_path / "missing.obj"}]
    manifest_csv = write_manifest(tmp_path / "pairs.csv", rows)
    read = vertexflow.read_batch_manifest(manifest_csv)
    assert [os.path.realpath(r["input"]) for r in read[: len(lod_pairs)]] == [os.path.realpath(c) for c, _ in lod_pairs]
    assert read[0]["output"] == str(tmp_path / "named" / lod_pairs[0][0].name) and read[1]["output"] is None

    (tmp_path / "named").mkdir()  # the batch creates output_dir, not a row's own directory
    out = tmp_path / "py"
    summary = vertexflow.batch(output_dir=out, manifest=manifest_csv, jobs=2, threads=1)
    assert summary["done"] == len(lod_pairs) and summary["failed"] == 2
    files = summary["files"]
    assert "has no reference" in files[-2]["error"] and "missing.obj" in files[-1]["error"]
    named = tmp_path / "named" / lod_pairs[0][0].name
    assert files[0]["output"] == str(named)
    for (coarse, dense), row in zip(lod_pairs, files):
        output = named if row is files[0] else out / coarse.name
        assert sha256(output) == lod_cli[coarse.name], coarse.name
        # The summary records the mode and the distances to the reference; the fit lowers the mean.
        assert row["mode"] == "reference" and row["reference"] == str(dense)
        distance = row["distance_to_reference"]["mean"]
        assert distance["result"] < distance["input"], coarse.name

    # The CLI's batch over the same rows as a JSON manifest, and reference_dir (matched by stem).
    manifest_json = write_manifest(tmp_path / "pairs.json", [{"input": c, "reference": d} for c, d in lod_pairs])
    run_cli("-q", "batch", "--manifest", manifest_json, tmp_path / "cli", "--jobs", "2", "--threads", "1")
    by_stem = vertexflow.batch(coarse_dir, tmp_path / "by_stem", reference_dir=DATA, jobs=2, threads=1)
    assert by_stem["done"] == len(lod_pairs)
    for coarse, _ in lod_pairs:
        assert sha256(tmp_path / "cli" / coarse.name) == lod_cli[coarse.name], coarse.name
        assert sha256(tmp_path / "by_stem" / coarse.name) == lod_cli[coarse.name], coarse.name


def bumpy_grids(directory, count):
    """count small bumpy height fields, each with its own bump: files for a batch to work on."""
    directory.mkdir()
    n = 9
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n))
    cells = [(i * n + j, i * n + j + 1, (i + 1) * n + j, (i + 1) * n + j + 1) for i in range(n - 1) for j in range(n - 1)]
    F = np.array([f for a, b, c, d in cells for f in ((a, b, d), (a, d, c))], dtype=np.int64)
    for k in range(count):
        z = 0.3 * np.exp(-((x - 0.1 * k) ** 2 + y**2) * 4)
        vertexflow.write_mesh(directory / f"grid{k}.obj", np.column_stack([x.ravel(), y.ravel(), z.ravel()]), F)
    return directory


@pytest.mark.parametrize("exception", [KeyboardInterrupt, ValueError])
def test_an_exception_in_the_progress_callback_stops_the_batch_and_is_raised(tmp_path, exception):
    # Issue 32 item 7: the exception was printed as "Exception ignored" once per file and the batch ran on.
    inputs = bumpy_grids(tmp_path / "in", 4)
    out = tmp_path / "out"
    calls = []

    def progress(p):
        calls.append(p)
        raise exception("stop here")

    with pytest.raises(exception, match="stop here"):
        vertexflow.batch(inputs, out, jobs=1, threads=1, progress=progress)
    assert len(calls) == 1  # not called again after it raised
    written = sorted(p.name for p in out.iterdir() if not p.name.startswith("batch_summary"))
    assert written == ["grid0.obj"]  # stopped at the next file boundary, what was written kept
    summary = json.loads((out / "batch_summary.json").read_text())
    assert [r["status"] for r in summary["files"]] == ["done"] and "stopped" in summary
    resumed = vertexflow.batch(inputs, out, jobs=1, threads=1)
    assert resumed["skipped"] == 1 and resumed["done"] == 3
    assert resumed["files"][0]["redistribution_rho"] == summary["files"][0]["redistribution_rho"]


def test_an_interrupt_with_two_jobs_stops_within_a_file_of_each(tmp_path):
    inputs = bumpy_grids(tmp_path / "in", 6)
    out = tmp_path / "out"

    def progress(p):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        vertexflow.batch(inputs, out, jobs=2, threads=1, progress=progress)
    # The file that raised, and at most the one the other job was working on.
    assert 1 <= len([p for p in out.iterdir() if p.suffix == ".obj"]) <= 2


def test_a_damaged_summary_is_a_warning_and_its_rows_are_measured_again(tmp_path):
    # Issue 32 item 4, through Python: one UserWarning naming the summary, every row measured.
    inputs = bumpy_grids(tmp_path / "in", 2)
    out = tmp_path / "out"
    first = vertexflow.batch(inputs, out, threads=1)
    text = (out / "batch_summary.json").read_text()
    (out / "batch_summary.json").write_text(text[: len(text) // 3])
    with pytest.warns(UserWarning, match="batch_summary.json: cannot read the earlier summary"):
        again = vertexflow.batch(inputs, out, threads=1)
    for old, new in zip(first["files"], again["files"]):
        assert new["status"] == "skipped"
        assert new["redistribution_rho"]["result"] == pytest.approx(old["redistribution_rho"]["result"], rel=1e-12)
        assert new["displacement_edge_lengths"]["max"] == pytest.approx(
            old["displacement_edge_lengths"]["max"], rel=1e-12)
