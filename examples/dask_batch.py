#!/usr/bin/env python3
"""Enhance a dataset of meshes with dask.distributed: `vertexflow batch` beyond one machine.

Each task is vertexflow.enhance_file(input, output): the per-file unit of `vertexflow batch`, so
the outputs are byte-identical to the batch's (and to `vertexflow enhance`'s) for the same
options. Workers read and write the paths they are given, so on a real cluster INPUT and
OUTPUT_DIR must be on storage every worker mounts at the same path (docs/scaling.md).

    # a LocalCluster of 2 worker processes on this machine (loopback only)
    PYTHONPATH=build/python python3 examples/dask_batch.py data/ out/ --workers 2 --threads 1
    # an existing cluster (dask-scheduler / dask-worker, see docs/scaling.md)
    python3 examples/dask_batch.py /shared/meshes /shared/out --scheduler tcp://10.0.0.1:8786

Failing files are reported and skipped; existing outputs are skipped unless --force (resumable).
A summary JSON (the rows of `vertexflow batch`'s batch_summary.json) goes to --summary, by default
OUTPUT_DIR/batch_summary.json.
"""

import argparse
import glob
import json
import os
import sys
import time


def list_inputs(spec):
    """As `vertexflow batch`: every regular, non-hidden file of a directory, or a glob, sorted."""
    if os.path.isdir(spec):
        names = sorted(n for n in os.listdir(spec) if not n.startswith("."))
        paths = [os.path.join(spec, n) for n in names]
        return [os.path.abspath(p) for p in paths if os.path.isfile(p)]
    return sorted(os.path.abspath(p) for p in glob.glob(spec) if os.path.isfile(p))


def enhance_one(input_path, output_path, options):
    """The task a worker runs; imported there, so workers need vertexflow on their PYTHONPATH."""
    import vertexflow

    return vertexflow.enhance_file(input_path, output_path, **options)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("input", help="directory (every file in it) or glob pattern of input meshes")
    parser.add_argument("output_dir", help="output directory on storage every worker sees")
    parser.add_argument("--scheduler", help="address of an existing scheduler (default: start a LocalCluster)")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    parser.add_argument("--threads", type=int, default=1,
                        help="library threads per task (default 1: one task per worker core)")
    parser.add_argument("--force", action="store_true", help="redo files whose output exists")
    parser.add_argument("--no-metrics", action="store_true", help="skip rho, CV, flips and displacement")
    parser.add_argument("--summary", help="summary JSON (default OUTPUT_DIR/batch_summary.json)")
    parser.add_argument("--lam", type=float, help="lambda of the flow (default the library's, 1)")
    parser.add_argument("--mu", type=float, help="mu of the flow (default 0.5)")
    parser.add_argument("--iterations", type=int, help="solves (default 1)")
    args = parser.parse_args(argv)

    from dask.distributed import Client, LocalCluster, as_completed

    inputs = list_inputs(args.input)
    if not inputs:
        sys.exit(f"dask_batch: error: {args.input}: no input files")
    output_dir = os.path.abspath(args.output_dir)
    os.makedirs(output_dir, exist_ok=True)
    names = [os.path.basename(p) for p in inputs]
    if len(set(names)) != len(names):
        sys.exit("dask_batch: error: two inputs have the same file name (their outputs would collide)")
    options = {"threads": args.threads, "force": args.force, "metrics": not args.no_metrics}
    for key in ("lam", "mu", "iterations"):
        if getattr(args, key) is not None:
            options[key] = getattr(args, key)

    # As `vertexflow batch`: a file skipped now keeps the row of the run that wrote its output.
    summary_path = args.summary or os.path.join(output_dir, "batch_summary.json")
    previous = {}
    try:
        with open(summary_path) as f:
            previous = {r["input"]: r for r in json.load(f)["files"] if r.get("vertices") is not None}
    except (OSError, ValueError, KeyError, TypeError):
        pass

    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        # Loopback only, no dashboard: nothing listens beyond this machine.
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None)
        client = Client(cluster)
    try:
        start = time.monotonic()
        futures = client.map(enhance_one, inputs, [os.path.join(output_dir, n) for n in names],
                             options=options, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        rows = [None] * len(inputs)
        failed = 0
        for finished, future in enumerate(as_completed(futures), 1):
            row = future.result()
            if row["status"] == "skipped" and row["input"] in previous:
                row = dict(previous[row["input"]], status="skipped")
            rows[index[future.key]] = row
            failed += row["status"] == "failed"
            elapsed = time.monotonic() - start
            eta = elapsed / finished * (len(inputs) - finished)
            if row["status"] == "failed":
                print(f"dask_batch: warning: {row['error']}", file=sys.stderr)
            print(f"dask_batch: {finished}/{len(inputs)} {os.path.basename(row['input'])} {row['status']}, "
                  f"ETA {eta:.0f} s", file=sys.stderr)
        seconds = time.monotonic() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    summary = {
        "done": sum(r["status"] == "done" for r in rows),
        "skipped": sum(r["status"] == "skipped" for r in rows),
        "failed": failed,
        "seconds": seconds,
        "meshes_per_second": len(rows) / seconds if seconds > 0 else None,
        "files": rows,
    }
    tmp = summary_path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=2)
        f.write("\n")
    os.replace(tmp, summary_path)  # atomic, as every output of vertexflow
    print(f"dask_batch: {summary['done']} done, {summary['skipped']} skipped, {failed} failed in {seconds:.2f} s "
          f"({summary['meshes_per_second']:.2f} meshes/s); summary in {summary_path}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
