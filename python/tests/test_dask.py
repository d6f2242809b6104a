"""examples/dask_batch.py on a 2-worker LocalCluster on loopback over the 20 data meshes: the
outputs are byte-identical to `vertexflow batch`'s."""

import json
import subprocess
import sys

from conftest import EXAMPLES, run_cli


def test_dask_local_cluster_matches_batch(dataset20, tmp_path):
    batch_out = tmp_path / "batch"
    run_cli("-q", "batch", dataset20, batch_out, "--jobs", "2", "--threads", "1", "--no-metrics")
    dask_out = tmp_path / "dask"
    summary = tmp_path / "dask_summary.json"
    result = subprocess.run(
        [sys.executable, EXAMPLES / "dask_batch.py", dataset20, dask_out, "--workers", "2", "--threads", "1",
         "--summary", summary],
        capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    rows = json.loads(summary.read_text())["files"]
    assert len(rows) == 20 and all(r["status"] == "done" for r in rows)
    names = sorted(p.name for p in dataset20.iterdir())
    assert sorted(p.name for p in dask_out.iterdir()) == names
    for name in names:
        assert (dask_out / name).read_bytes() == (batch_out / name).read_bytes(), name
