"""Shared fixtures of the Python test suite: paths from the environment ctest sets
(python/CMakeLists.txt), a dataset of 20 small bundled meshes for the batch and Dask tests, and
(coarse, dense) pairs for the reference-mode batches (the level-of-detail pipeline)."""

import csv
import hashlib
import json
import os
import pathlib
import shutil
import subprocess

import pytest

import vertexflow

DATA = pathlib.Path(os.environ.get("VERTEXFLOW_DATA_DIR", pathlib.Path(__file__).resolve().parents[2] / "data")).resolve()
CLI = os.environ.get("VERTEXFLOW_CLI", "vertexflow")
STUB_DIR = pathlib.Path(os.environ.get("VERTEXFLOW_STUB_DIR", pathlib.Path(__file__).resolve().parents[1] / "stub"))
EXAMPLES = pathlib.Path(os.environ.get("VERTEXFLOW_EXAMPLES_DIR", pathlib.Path(__file__).resolve().parents[2] / "examples"))

# The 17 bundled meshes below 12k vertices (data/README.md), in every format the data has.
SMALL_MESHES = [
    "amo_adaptive.off", "bunny_adaptive.off", "bunny_uniform.off", "camelhead.off", "chamfer-cube.off",
    "fandisk.off", "fandisk_quads.off", "fertility.off", "hemisphere.off", "icosahedron_ascii.stl",
    "icosahedron_binary.stl", "max-planck-5k.obj", "rocker-arm.obj", "sphere_low.off", "spot.obj",
    "suzanne.obj", "torus.obj",
]
# Three more, converted to the formats the others lack (binary PLY, gzip OFF, binary STL).
CONVERTED = {"spot_copy.ply": "spot.obj", "torus_copy.off.gz": "torus.obj", "sphere_low_copy.stl": "sphere_low.off"}


def make_dataset(directory: pathlib.Path) -> list[pathlib.Path]:
    """Writes the 20 meshes into `directory` and returns their paths."""
    directory.mkdir(parents=True, exist_ok=True)
    for name in SMALL_MESHES:
        shutil.copy(DATA / name, directory / name)
    for name, source in CONVERTED.items():
        V, F = vertexflow.read_mesh(DATA / source)
        vertexflow.write_mesh(directory / name, V, F)
    return sorted(directory.iterdir())


@pytest.fixture(scope="session")
def dataset20(tmp_path_factory) -> pathlib.Path:
    directory = tmp_path_factory.mktemp("dataset20")
    assert len(make_dataset(directory)) == 20
    return directory


def run_cli(*args, check=True):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, check=check)


def sha256(path) -> str:
    return hashlib.sha256(pathlib.Path(path).read_bytes()).hexdigest()


def cli_flags(options: dict) -> list[str]:
    """The CLI's flags for Python keywords, through the option table (a bool flag sets the opposite
    of its default, so it is given only for that value)."""
    flags = []
    for name, value in options.items():
        option = vertexflow.ENHANCE_OPTIONS[name]
        assert option.flag, name
        if option.kind == "bool":
            assert value != option.default, name
            flags.append(option.flag)
        else:
            flags += [option.flag, str(value)]
    return flags


# (coarse, dense): two adaptive remeshes bundled with their originals, two isotropic remeshes and a
# QEM decimation made here, at 2-6k vertices. Each coarse file takes its dense original's name, so
# reference_dir=DATA finds it by stem.
LOD_PAIRS = [
    ("bunny_adaptive.off", "bunny.off"),
    ("amo_adaptive.off", "amo.off"),
    ("remesh", "horse-48k.ply"),
    ("remesh", "sphere.off"),
    ("simplify", "armadillo-43k.obj"),
]


@pytest.fixture(scope="session")
def lod_pairs(tmp_path_factory) -> list[tuple[pathlib.Path, pathlib.Path]]:
    """[(coarse, dense)] paths, the coarse meshes in one directory."""
    directory = tmp_path_factory.mktemp("coarse")
    pairs = []
    for source, dense in LOD_PAIRS:
        coarse = directory / dense
        if source == "remesh":
            vertexflow.write_mesh(coarse, *vertexflow.remesh(*vertexflow.read_mesh(DATA / dense), target_vertices=2000))
        elif source == "simplify":
            vertexflow.write_mesh(coarse, *vertexflow.simplify(*vertexflow.read_mesh(DATA / dense), faces=4000))
        else:
            shutil.copy(DATA / source, coarse)
        pairs.append((coarse, DATA / dense))
    return pairs


def write_manifest(path: pathlib.Path, rows: list[dict]) -> pathlib.Path:
    """A batch manifest: CSV (header input,reference,output) or JSON, by the extension."""
    if path.suffix == ".json":
        path.write_text(json.dumps([{k: str(v) if v else None for k, v in r.items()} for r in rows]))
    else:
        with open(path, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=["input", "reference", "output"])
            writer.writeheader()
            writer.writerows({k: str(r.get(k) or "") for k in ("input", "reference", "output")} for r in rows)
    return path


def cli_reference_outputs(pairs, directory: pathlib.Path) -> dict[str, str]:
    """`vertexflow enhance COARSE OUT --reference DENSE` for each pair -> {file name: sha256}."""
    directory.mkdir(parents=True, exist_ok=True)
    hashes = {}
    for coarse, dense in pairs:
        run_cli("-q", "enhance", coarse, directory / coarse.name, "--reference", dense)
        hashes[coarse.name] = sha256(directory / coarse.name)
    return hashes
