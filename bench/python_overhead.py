#!/usr/bin/env python3
"""Python call overhead of vertexflow.enhance over the C++ call vertex_flow on a 10k-vertex mesh.

Both are timed in one process, interleaved (C++, Python, C++, ...) so that the machine's load
hits both alike: the C++ side is vertexflow._time_vertex_flow (vertex_flow called from C++ on
matrices already in Eigen, what a C++ program pays), the Python side vertexflow.enhance(V, F)
from Python (array checks, the copy into the library's matrices, the GIL release, the result's
array and the report dict). Overhead = median(Python) / median(C++) - 1.

    PYTHONPATH=build/python python3 bench/python_overhead.py [--mesh data/rocker-arm.obj] [--repeats 21]
"""

import argparse
import os
import statistics
import time

import vertexflow

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--mesh", default=os.path.join(DATA, "rocker-arm.obj"), help="10,044 vertices by default")
    parser.add_argument("--repeats", type=int, default=21)
    parser.add_argument("--threads", type=int, default=0, help="0: all cores")
    args = parser.parse_args()
    V, F = vertexflow.read_mesh(args.mesh)
    # Warm up both paths (allocator, page faults, TBB's threads).
    vertexflow._time_vertex_flow(V, F, 2, args.threads)
    vertexflow.enhance(V, F, threads=args.threads)
    cpp, py = [], []
    for _ in range(args.repeats):
        cpp.extend(vertexflow._time_vertex_flow(V, F, 1, args.threads))
        start = time.perf_counter()
        vertexflow.enhance(V, F, threads=args.threads)
        py.append(time.perf_counter() - start)
    c, p = statistics.median(cpp), statistics.median(py)
    print(f"mesh {os.path.basename(args.mesh)}: {len(V)} vertices, {len(F)} faces; {args.repeats} calls each, "
          f"threads={args.threads}, load average {os.getloadavg()[0]:.2f}")
    print(f"C++ vertex_flow   median {c * 1e3:8.2f} ms  (min {min(cpp) * 1e3:.2f})")
    print(f"Python enhance    median {p * 1e3:8.2f} ms  (min {min(py) * 1e3:.2f})")
    print(f"overhead          {100 * (p / c - 1):+.2f}% of the median (min: {100 * (min(py) / min(cpp) - 1):+.2f}%)")


if __name__ == "__main__":
    main()
