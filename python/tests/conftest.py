"""Shared fixtures of the Python test suite: paths from the environment ctest sets
(python/CMakeLists.txt), and a dataset of 20 small bundled meshes for the batch and Dask tests."""

import os
import pathlib
import shutil
import subprocess

import pytest

import vertexflow

DATA = pathlib.Path(os.environ.get("VERTEXFLOW_DATA_DIR", pathlib.Path(__file__).resolve().parents[2] / "data"))
CLI = os.environ.get("VERTEXFLOW_CLI", "vertexflow")
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
