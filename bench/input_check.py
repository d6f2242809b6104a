#!/usr/bin/env python3
"""The measurements behind the input check of `vertexflow enhance` (issue 30, input_check.h).

For three kinds of input it prints, as Markdown, the two measures of the check (the share of faces
below quality 0.3 and the share of interior edges sharper than 40 degrees, as the report's "hold"
section records them), the decision, and the two-sided mean distance to the true surface before
and after the paper's flow, 30 density passes and smooth mode, each as run by default (held or
not) and with --assume-on-surface:
  - QEM simplifications (`vertexflow simplify`) of data/ meshes at 10% and 25% of their faces,
    against the dense mesh;
  - control meshes against their subdivision surfaces (build/bin/subdivide: CGAL's Loop or
    Catmull-Clark), from data/ meshes and coarse `vertexflow remesh` outputs;
  - meshes whose vertices lie on the surface: the data/ meshes, and the uniform remeshes of Fig. 12
    and of the PMP comparison against their dense meshes.

    python3 bench/input_check.py [--build build] [--work build/input_check] > table.md
"""
import argparse
import json
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "data"

QEM = ["bunny.off", "amo.off", "armadillo-43k.obj", "horse-48k.ply", "rocker-arm.obj", "fertility.off",
       "spot.obj", "torus.obj", "camelhead.off"]
# (name, control mesh (a data/ file, or a remesh of one: (dense, vertices)), scheme, iterations)
CAGES = [("icosahedron", "icosahedron_ascii.stl", "loop", 5), ("chamfer-cube", "chamfer-cube.off", "catmull-clark", 5),
         ("suzanne", "suzanne.obj", "catmull-clark", 3), ("fandisk_quads", "fandisk_quads.off", "catmull-clark", 3),
         ("bunny-remesh-500", ("bunny.off", 500), "loop", 4), ("fertility-remesh-1000", ("fertility.off", 1000), "loop", 3),
         # The same meshes are also remeshes or subdivision output of other surfaces: not held.
         ("bunny-remesh-2000", ("bunny.off", 2000), "loop", 3), ("spot", "spot.obj", "loop", 2),
         ("torus", "torus.obj", "loop", 2), ("sphere_low", "sphere_low.off", "loop", 3)]
REMESHES = [("bunny", "bunny.off", 6000), ("amo", "amo.off", 6000), ("armadillo", "armadillo-43k.obj", 6000),
            ("horse", "horse-48k.ply", 6000), ("bunny", "bunny.off", 5884), ("amo", "amo.off", 5677)]
PAIRS = [("bunny_uniform.off", "bunny.off"), ("bunny_adaptive.off", "bunny.off"), ("amo_adaptive.off", "amo.off")]
OTHERS = ["fandisk.off", "spot.obj", "torus.obj", "sphere_low.off", "hemisphere.off", "rocker-arm.obj",
          "armadillo-43k.obj", "horse-48k.ply", "fertility.off", "camelhead.off", "max-planck-5k.obj", "suzanne.obj",
          "fandisk_quads.off", "chamfer-cube.off"]
MODES = [("flow", []), ("density 30", ["--density-passes", "30"]), ("smooth", ["--surface", "smooth"])]


class Runner:
    def __init__(self, build, work):
        self.cli, self.subdivide, self.work = build / "bin" / "vertexflow", build / "bin" / "subdivide", work
        work.mkdir(parents=True, exist_ok=True)

    def run(self, *args):
        return subprocess.run([str(a) for a in args], check=True, capture_output=True, text=True).stdout

    def made(self, name, *command):
        out = self.work / name
        if not out.exists():
            self.run(*command)
        return out

    def enhance(self, mesh, name, *options):
        out, report = self.work / f"{name}.ply", self.work / f"{name}.json"
        self.run(self.cli, "--quiet", "enhance", mesh, out, "--force", "--report", report, *options)
        return out, json.loads(report.read_text())

    def mean(self, mesh, truth):
        c = json.loads(self.run(self.cli, "compare", mesh, mesh, "--reference", truth, "--json", "--samples", 100000))
        d = c["distance"]["result_reference"]
        return 0.5 * (d["result_to_reference"]["mean"] + d["reference_to_result"]["mean"])

    def row(self, label, mesh, truth, name):
        """The check's measures and decision, and the distance changes of each mode, default and assumed."""
        _, report = self.enhance(mesh, f"{name}-flow")
        hold = report["hold"]
        cells = [label, f"{100 * hold['poor_face_fraction']:.2f}%", f"{100 * hold['sharp_edge_fraction']:.1f}%",
                 hold["reason"] or "-"]
        if truth is None:
            return cells
        base = self.mean(mesh, truth)
        cells.append(f"{base:.4g}")
        for mode, options in MODES:
            changes = []
            for assumed in ([], ["--assume-on-surface"]):
                if mode == "density 30" and not assumed:
                    continue  # as the flow's decision
                out, _ = self.enhance(mesh, f"{name}-{mode}{'-assumed' if assumed else ''}".replace(" ", ""),
                                      *options, *assumed)
                changes.append(f"{100 * (self.mean(out, truth) / base - 1):+.1f}%")
            cells.append(" / ".join(changes))
        return cells


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(map(str, r)) + " |" for r in rows])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", type=Path, default=ROOT / "build")
    parser.add_argument("--work", type=Path, default=ROOT / "build" / "input_check")
    args = parser.parse_args()
    r = Runner(args.build, args.work)
    header = ["input", "faces < 0.3", "edges > 40 deg", "held as", "mean distance to truth",
              "flow: default / assumed", "density 30: assumed", "smooth: default / assumed"]

    rows = []
    for name in QEM:
        stem = name.rsplit(".", 1)[0]
        for ratio in ("0.10", "0.25"):
            q = r.made(f"qem-{stem}-{ratio}.ply", r.cli, "--quiet", "simplify", DATA / name,
                       args.work / f"qem-{stem}-{ratio}.ply", "--ratio", ratio, "--force")
            rows.append(r.row(f"{stem} QEM {float(ratio):.0%}", q, DATA / name, f"qem-{stem}-{ratio}"))
    print("## QEM simplifications, against the dense mesh\n\n" + table(header, rows) + "\n")

    rows = []
    for name, source, scheme, iterations in CAGES:
        if isinstance(source, tuple):
            dense, vertices = source
            cage = r.made(f"cage-{name}.off", r.cli, "--quiet", "remesh", DATA / dense, args.work / f"cage-{name}.off",
                          "--target-vertices", vertices, "--force")
        else:
            cage = DATA / source
        truth = r.made(f"truth-{name}.off", r.subdivide, cage, args.work / f"truth-{name}.off", scheme, iterations)
        rows.append(r.row(f"{name} ({scheme} x{iterations})", cage, truth, f"cage-{name}"))
    print("## Control meshes, against their subdivision surfaces\n\n" + table(header, rows) + "\n")

    rows = []
    for name, dense, vertices in REMESHES:
        mesh = r.made(f"remesh-{name}-{vertices}.ply", r.cli, "--quiet", "remesh", DATA / dense,
                      args.work / f"remesh-{name}-{vertices}.ply", "--target-vertices", vertices, "--force")
        rows.append(r.row(f"{name} remesh {vertices}", mesh, DATA / dense, f"remesh-{name}-{vertices}"))
    for name, dense in PAIRS:
        rows.append(r.row(name, DATA / name, DATA / dense, f"pair-{name}"))
    for name in OTHERS:
        rows.append(r.row(name, DATA / name, None, f"data-{name}") + ["", "", "", ""])
    print("## Meshes whose vertices lie on a surface (and the other data/ meshes)\n\n" + table(header, rows))


if __name__ == "__main__":
    main()
