#!/usr/bin/env python3
"""Enhance a dataset of meshes with dask.distributed: `vertexflow batch` beyond one machine.

Each task is vertexflow.enhance_file(input, output, reference=...): the per-file unit of
`vertexflow batch`, so the outputs are byte-identical to the batch's (and to `vertexflow
enhance`'s) for the same options, in any mode. The files come as for `vertexflow batch`: a
directory or glob INPUT, or --manifest FILE, a CSV (header input,reference,output) or JSON (a
list of {input, reference, output}) whose rows with a reference run a reference mode (the
level-of-detail pipeline: coarse meshes fitted to their dense originals). The enhance options
are `vertexflow batch`'s flags (--lambda, --surface, --edge-flips, ...). Workers read and write
the paths they are given, so on a real cluster the files must be on storage every worker mounts
at the same path (docs/scaling.md).

    # a LocalCluster of 2 worker processes on this machine (loopback only)
    PYTHONPATH=build/python python3 examples/dask_batch.py data/ out/ --workers 2 --threads 1
    PYTHONPATH=build/python python3 examples/dask_batch.py out/ --manifest pairs.csv --max-rounds 5
    # an existing cluster (dask-scheduler / dask-worker, see docs/scaling.md)
    python3 examples/dask_batch.py /shared/meshes /shared/out --scheduler tcp://10.0.0.1:8786

Failing files are reported and skipped; existing outputs are skipped unless --force (resumable).
A summary JSON (the rows of `vertexflow batch`'s batch_summary.json) goes to --summary, by default
OUTPUT_DIR/batch_summary.json.
"""

import argparse
import json
import os
import sys
import time


def enhance_one(input_path, output_path, reference, options):
    """The task a worker runs; imported there, so workers need vertexflow on their PYTHONPATH."""
    import vertexflow

    return vertexflow.enhance_file(input_path, output_path, reference=reference, **options)


def add_enhance_flags(parser, vertexflow):
    """One flag per option of the library's table that the CLI has a flag for, as `vertexflow batch`."""
    group = parser.add_argument_group("enhance options (those of `vertexflow batch`)")
    for option in vertexflow.ENHANCE_OPTIONS.values():
        if not option.flag:
            continue
        common = {"dest": option.name, "default": argparse.SUPPRESS, "help": option.help.replace("%", "%%")}
        if option.kind == "bool":
            # A flag sets the opposite of the default (--free-boundary, --no-projection, --edge-flips).
            group.add_argument(option.flag, action="store_const", const=not option.default, **common)
        elif option.kind == "choice":
            group.add_argument(option.flag, choices=option.choices, **common)
        else:
            group.add_argument(option.flag, type=float if option.kind == "float" else int, **common)


def main(argv=None):
    import vertexflow

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("input", nargs="?", help="directory (its mesh files) or glob pattern of input meshes; "
                        "leave it out with --manifest")
    parser.add_argument("output_dir", nargs="?", help="output directory on storage every worker sees")
    parser.add_argument("--manifest", help="CSV or JSON rows of input, reference, output (as `vertexflow batch`)")
    parser.add_argument("--scheduler", help="address of an existing scheduler (default: start a LocalCluster)")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    parser.add_argument("--threads", type=int, default=1,
                        help="library threads per task (default 1: one task per worker core)")
    parser.add_argument("--force", action="store_true", help="redo files whose output exists")
    parser.add_argument("--no-metrics", action="store_true", help="skip rho, CV, flips, displacement and distances")
    parser.add_argument("--summary", help="summary JSON (default OUTPUT_DIR/batch_summary.json)")
    add_enhance_flags(parser, vertexflow)
    args = parser.parse_args(argv)
    # As `vertexflow batch`: with --manifest and one positional, it is OUTPUT_DIR.
    if args.manifest and args.output_dir is None:
        args.input, args.output_dir = None, args.input
    if args.output_dir is None:
        parser.error("OUTPUT_DIR is required")
    if bool(args.manifest) == bool(args.input):
        parser.error("give INPUT (a directory or glob) or --manifest FILE, not both" if args.manifest
                     else "give INPUT (a directory or glob) or --manifest FILE")

    output_dir = os.path.abspath(args.output_dir)
    try:
        if args.manifest:
            rows = vertexflow.read_batch_manifest(args.manifest)
        else:
            rows = [{"input": p, "reference": None, "output": None} for p in vertexflow.batch_inputs(args.input)]
    except OSError as e:
        sys.exit(f"dask_batch: error: {e}")
    if not rows:
        sys.exit("dask_batch: error: no input files")
    items = [(os.path.abspath(r["input"]), r["reference"] and os.path.abspath(r["reference"]),
              os.path.abspath(r["output"] or os.path.join(output_dir, os.path.basename(r["input"])))) for r in rows]
    outputs = [output for _, _, output in items]
    if len(set(outputs)) != len(outputs):
        sys.exit("dask_batch: error: two inputs have the same output (one would overwrite the other)")
    # As `vertexflow batch`: a reference mode when any file has a reference; the options' mode
    # rules are checked once, before the cluster starts.
    reference_mode = any(reference for _, reference, _ in items)
    table_options = {name: getattr(args, name) for name in vertexflow.ENHANCE_OPTIONS if hasattr(args, name)}
    try:
        vertexflow.enhance_options(has_reference=reference_mode, naming="cli", **table_options)
    except ValueError as e:
        parser.error(str(e))
    options = dict(table_options, threads=args.threads, force=args.force, metrics=not args.no_metrics)
    os.makedirs(output_dir, exist_ok=True)

    # As `vertexflow batch`: a file skipped now keeps the row of the run that wrote its output.
    summary_path = args.summary or os.path.join(output_dir, "batch_summary.json")
    previous = {}
    try:
        with open(summary_path) as f:
            previous = {r["input"]: r for r in json.load(f)["files"] if r.get("vertices") is not None}
    except (OSError, ValueError, KeyError, TypeError):
        pass

    rows = [None] * len(items)
    todo = []
    for i, (input_path, reference, output) in enumerate(items):
        if reference_mode and not reference:
            rows[i] = {"input": input_path, "output": output, "reference": None, "status": "failed",
                       "error": f"{input_path}: has no reference (a reference mode needs one per file)"}
        else:
            todo.append(i)

    from dask.distributed import Client, LocalCluster, as_completed

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
        futures = client.map(enhance_one, *zip(*[(items[i][0], items[i][2], items[i][1]) for i in todo]),
                             options=options, pure=False) if todo else []
        index = {f.key: i for i, f in zip(todo, futures)}
        for finished, future in enumerate(as_completed(futures), 1):
            row = future.result()
            if row["status"] == "skipped" and row["input"] in previous:
                row = dict(previous[row["input"]], status="skipped")
            rows[index[future.key]] = row
            elapsed = time.monotonic() - start
            eta = elapsed / finished * (len(futures) - finished)
            if row["status"] == "failed":
                print(f"dask_batch: warning: {row['error']}", file=sys.stderr)
            print(f"dask_batch: {finished}/{len(futures)} {os.path.basename(row['input'])} {row['status']}, "
                  f"ETA {eta:.0f} s", file=sys.stderr)
        seconds = time.monotonic() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    failed = sum(r["status"] == "failed" for r in rows)
    summary = {
        "done": sum(r["status"] == "done" for r in rows),
        "skipped": sum(r["status"] == "skipped" for r in rows),
        "failed": failed,
        "seconds": seconds,
        "meshes_per_second": len(rows) / seconds if seconds > 0 else None,
        "options": vertexflow.enhance_options(has_reference=reference_mode, **table_options),
        "files": rows,
    }
    tmp = summary_path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=2)
        f.write("\n")
    os.replace(tmp, summary_path)  # atomic, as every output of vertexflow
    print(f"dask_batch: {summary['done']} done, {summary['skipped']} skipped, {failed} failed in {seconds:.2f} s "
          f"({summary['meshes_per_second'] or 0:.2f} meshes/s); summary in {summary_path}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
