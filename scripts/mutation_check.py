#!/usr/bin/env python3
"""Sabotages the flow on purpose and checks that the test suite notices (docs/testing.md).

Each mutation below is a small edit of src/ that breaks one promise of the flow. For each one
asked for, the script applies it, builds, runs ctest (without the slow tests that do not run the
flow), restores src/ with `git checkout`, and prints the tests that failed. A mutation that no
test catches is a hole in the suite: the script exits 1.

    scripts/mutation_check.py [--build-dir build] [MUTATION ...]   # default: all

Refuses to run when src/ has uncommitted changes, since it restores src/ from git.
"""
import argparse
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# name -> (file, text to replace, replacement, what it breaks)
MUTATIONS = {
    "identity": ("src/flow/flow.cpp",
                 "  return result;\n}\n\n}  // namespace vertexflow",
                 "  result.V = V;\n  return result;\n}\n\n}  // namespace vertexflow",
                 "vertex_flow returns its input"),
    "guard_restores": ("src/flow/guard.cpp",
                       "  const Vertices displacement = X - anchor;",
                       "  X = anchor;\n  const Vertices displacement = X - anchor;",
                       "the guard puts every vertex back where the round started"),
    "skip_creases": ("src/flow/surface_projection.cpp",
                     "} else if (kind == SurfaceFeatures::Kind::Crease) {",
                     "} else if (false && kind == SurfaceFeatures::Kind::Crease) {",
                     "the projection treats crease vertices as smooth ones"),
    "floor_zero": ("src/flow/guard.cpp",
                   "    criteria.quality_floor[f] = floor;",
                   "    criteria.quality_floor[f] = 0.0 * floor;",
                   "the guard's quality floor is 0"),
    "mu_ignored": ("src/flow/flow.cpp",
                   "    X = solver.solve(frame, options.weights, report);",
                   "    EnergyWeights no_fairness = options.weights;\n    no_fairness.mu = 0;\n"
                   "    X = solver.solve(frame, no_fairness, report);",
                   "the fairness weight mu is ignored"),
    "blas_two_threads": ("src/numerics/sparse_cholesky.cpp",
                         "      set(1);",
                         "      set(2);",
                         "the direct solve runs with two BLAS threads"),
}

# Tests that never run the flow and take minutes.
EXCLUDED = "fuzz_regression_replay|install_and_consume|html_report_browser|KilledWrite|MemoryLimit"


def run(command, **kwargs):
    return subprocess.run(command, cwd=ROOT, text=True, capture_output=True, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build-dir", default="build")
    parser.add_argument("mutations", nargs="*", choices=[[], *MUTATIONS], default=[])
    args = parser.parse_args()
    if run(["git", "diff", "--quiet", "--", "src"]).returncode != 0:
        sys.exit("mutation_check: src/ has uncommitted changes; commit or stash them first")
    uncaught = []
    for name in args.mutations or list(MUTATIONS):
        path, old, new, what = MUTATIONS[name]
        file = ROOT / path
        text = file.read_text()
        if text.count(old) != 1:
            sys.exit(f"mutation_check: {name}: the text to replace is not in {path} exactly once; update the script")
        try:
            file.write_text(text.replace(old, new))
            build = run(["cmake", "--build", args.build_dir])
            if build.returncode != 0:
                sys.exit(f"mutation_check: {name}: the build failed:\n{build.stdout[-2000:]}")
            tests = run(["ctest", "--test-dir", args.build_dir, "-j2", "-E", EXCLUDED])
        finally:
            run(["git", "checkout", "--", path])
        failed = [re.sub(r"\s+#.*|\s+\(Failed\)", "", line.split(" - ", 1)[1])
                  for line in tests.stdout.splitlines() if re.match(r"^\s+\d+ - ", line)]
        print(f"{name} ({what}): {len(failed)} tests fail")
        for test in failed:
            print(f"    {test}")
        if not failed:
            uncaught.append(name)
    run(["cmake", "--build", args.build_dir])  # the binaries of the restored sources
    if uncaught:
        sys.exit(f"mutation_check: no test caught: {', '.join(uncaught)}")


if __name__ == "__main__":
    main()
