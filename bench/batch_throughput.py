#!/usr/bin/env python3
"""Throughput, in meshes per second, of `vertexflow batch --jobs 1`, `--jobs 2` and
examples/dask_batch.py on a 2-worker LocalCluster, over the 20 small data meshes of the Python
tests (python/tests/conftest.py: the 17 bundled meshes below 12k vertices and 3 converted
copies), each file with one library thread (--threads 1), metrics on (the default) or off (--no-metrics).

    PYTHONPATH=build/python python3 bench/batch_throughput.py [--cli build/bin/vertexflow] [--repeats 3]

Two figures per setting: the batch's own seconds (the summary's "seconds": files only) and the
whole command's wall time (process start, for Dask the cluster's start and stop too).
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "python", "tests"))
from conftest import make_dataset  # noqa: E402  (the tests' dataset, one definition)

import pathlib  # noqa: E402


def run(command, summary):
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.perf_counter() - start
    data = json.loads(pathlib.Path(summary).read_text())
    assert data["done"] == 20, data
    return data["seconds"], wall


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cli", default=os.path.join(HERE, "..", "build", "bin", "vertexflow"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-metrics", action="store_true", help="pass --no-metrics to all three")
    args = parser.parse_args()
    extra = ["--no-metrics"] if args.no_metrics else []
    with tempfile.TemporaryDirectory() as tmp:
        data = pathlib.Path(tmp) / "data"
        make_dataset(data)
        out = pathlib.Path(tmp) / "out"
        settings = {
            "batch --jobs 1": lambda: run([args.cli, "-q", "batch", data, out, "--jobs", "1", "--threads", "1", "--force",
                                           *extra], out / "batch_summary.json"),
            "batch --jobs 2": lambda: run([args.cli, "-q", "batch", data, out, "--jobs", "2", "--threads", "1", "--force",
                                           *extra], out / "batch_summary.json"),
            "dask LocalCluster, 2 workers": lambda: run(
                [sys.executable, os.path.join(HERE, "..", "examples", "dask_batch.py"), data, out, "--workers", "2",
                 "--threads", "1", "--force", "--summary", pathlib.Path(tmp) / "dask.json", *extra], pathlib.Path(tmp) / "dask.json"),
        }
        print(f"20 meshes, metrics {'off' if extra else 'on'}, {os.cpu_count()} cores, load average before {os.getloadavg()[0]:.2f}; median of {args.repeats}")
        # Round-robin over the settings, so that a change of the machine's load hits all alike.
        runs = {name: [] for name in settings}
        for _ in range(args.repeats):
            for name, setting in settings.items():
                runs[name].append(setting())
        for name in settings:
            files = statistics.median(r[0] for r in runs[name])
            wall = statistics.median(r[1] for r in runs[name])
            print(f"{name:32s} {20 / files:6.2f} meshes/s over the files ({files:.2f} s), "
                  f"{20 / wall:6.2f} meshes/s whole command ({wall:.2f} s)")
        print(f"load average after {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
