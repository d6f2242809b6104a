"""examples/dask_batch.py on a 2-worker LocalCluster on loopback: over the 20 data meshes, the
outputs are byte-identical to `vertexflow batch`'s; over a manifest of (coarse, dense) pairs, to
`vertexflow enhance --reference`'s."""

import json
import subprocess
import sys

from conftest import EXAMPLES, cli_reference_outputs, run_cli, sha256, write_manifest


def run_dask(*args):
    result = subprocess.run([sys.executable, EXAMPLES / "dask_batch.py", *map(str, args)], capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    return result


def test_dask_local_cluster_matches_batch(dataset20, tmp_path):
    batch_out = tmp_path / "batch"
    run_cli("-q", "batch", dataset20, batch_out, "--jobs", "2", "--threads", "1", "--no-metrics")
    dask_out = tmp_path / "dask"
    summary = tmp_path / "dask_summary.json"
    run_dask(dataset20, dask_out, "--workers", "2", "--threads", "1", "--summary", summary)
    rows = json.loads(summary.read_text())["files"]
    assert len(rows) == 20 and all(r["status"] == "done" for r in rows)
    names = sorted(p.name for p in dataset20.iterdir())
    assert sorted(p.name for p in dask_out.iterdir()) == names
    for name in names:
        assert (dask_out / name).read_bytes() == (batch_out / name).read_bytes(), name


def test_dask_over_a_manifest_of_pairs_matches_enhance_reference(lod_pairs, tmp_path):
    cli = cli_reference_outputs(lod_pairs, tmp_path / "cli")
    manifest = write_manifest(tmp_path / "pairs.csv", [{"input": c, "reference": d} for c, d in lod_pairs])
    # As `vertexflow batch --manifest`: the one positional is the output directory.
    run_dask(tmp_path / "dask", "--manifest", manifest, "--workers", "2", "--threads", "1")
    summary = json.loads((tmp_path / "dask" / "batch_summary.json").read_text())
    assert summary["done"] == len(lod_pairs) >= 4 and summary["failed"] == 0
    assert all(r["mode"] == "reference" for r in summary["files"])
    for coarse, _ in lod_pairs:
        assert sha256(tmp_path / "dask" / coarse.name) == cli[coarse.name], coarse.name
    # The table's flags reach the workers, and a flag the mode does not take is refused up front.
    run_dask(tmp_path / "rounds", "--manifest", manifest, "--workers", "2", "--max-rounds", "1")
    rows = json.loads((tmp_path / "rounds" / "batch_summary.json").read_text())["files"]
    assert all(r["status"] == "done" for r in rows)
    assert any(sha256(tmp_path / "rounds" / c.name) != cli[c.name] for c, _ in lod_pairs)
    refused = subprocess.run([sys.executable, EXAMPLES / "dask_batch.py", tmp_path / "no", "--manifest", manifest,
                              "--lambda", "2"], capture_output=True, text=True, timeout=60)
    assert refused.returncode == 2 and "--lambda does not apply to --reference" in refused.stderr
    assert not (tmp_path / "no").exists()
