#!/usr/bin/env python3
"""The heap live at a run's peak, by allocation site (issue 29, docs/benchmarks.md "Memory by phase").

    heaptrack -o /tmp/vf29/h1m build/bin/vertexflow enhance /tmp/vf29/arm1m.ply /tmp/vf29/out.ply
    heaptrack_print -f /tmp/vf29/h1m.zst -p 0 -a 0 -T 0 -F /tmp/vf29/h1m.stacks --flamegraph-cost-type peak
    bench/heaptrack_peak.py /tmp/vf29/h1m.stacks [--depth 2] [--top 30] [--vertices 1081027]

heaptrack_print's flame-graph output with --flamegraph-cost-type peak holds, per call stack, the
bytes that stack had live at the moment the whole heap peaked. This sums them by the innermost
`depth` frames that are project code (frames of std::, Eigen::, CGAL::, tbb:: and the allocator
are skipped, so a vector's growth counts for the function that owns the vector), and with
--vertices also prints bytes per vertex.
"""
import argparse
import collections
import re

LIBRARY = re.compile(r"^(void |bool |auto )?(std::|Eigen::|tbb::|CGAL::|boost::|operator new|malloc|calloc|realloc|"
                     r"__gnu_cxx::|0x)")
ROOTS = {"main", "__libc_start_main", "__libc_start_call_main", "_start", "start_thread", "clone3",
         "CLI::App::parse", "CLI::App::_parse", "CLI::App::run_callback", "CLI::App::_process_callbacks"}


def frame_name(frame):
    name = frame.strip().replace("(anonymous namespace)", "anon")
    return name.split("(")[0].strip()  # without the parameter list


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stacks")
    parser.add_argument("--depth", type=int, default=2)
    parser.add_argument("--top", type=int, default=30)
    parser.add_argument("--vertices", type=int, default=0)
    args = parser.parse_args()

    sites = collections.Counter()
    for line in open(args.stacks):
        stack, _, value = line.rstrip("\n").rpartition(" ")
        if not value.isdigit() or int(value) == 0:
            continue
        frames = [frame_name(f) for f in stack.split(";")]
        own = [f for f in frames if f and not LIBRARY.match(f) and f not in ROOTS]
        if own:
            key = " <- ".join(reversed(own[-args.depth:]))
        else:  # a worker thread's stack that unwinds through library frames only
            inner = [f for f in frames if f and not re.match(r"^(operator new|malloc|calloc|realloc|0x)", f)]
            key = "(library frames only) " + (inner[-1] if inner else frames[-1])
        sites[key] += int(value)
    total = sum(sites.values())
    per_vertex = f", {total / args.vertices:.0f} B/vertex" if args.vertices else ""
    print(f"heap at the peak: {total / 2**20:.1f} MiB{per_vertex}")
    for key, value in sites.most_common(args.top):
        extra = f" {value / args.vertices:6.0f} B/v" if args.vertices else ""
        print(f"{value / 2**20:9.1f} MiB{extra}  {key[:240]}")


if __name__ == "__main__":
    main()
