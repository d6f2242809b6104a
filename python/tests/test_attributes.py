"""Mesh attributes in Python (issue 28): read_mesh(attributes=True) returns them as a dict
(vertexflow.MeshAttributes), write_mesh writes them back value for value, enhance takes them and
returns them re-sampled, and a bad dict raises ValueError naming its problem."""

import re

import warnings

import numpy as np
import pytest

import vertexflow
from conftest import DATA

# A tetrahedron: four vertices, four faces.
V_TET = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
F_TET = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32)

# Each type's extremes and a value between, as a PLY holds them.
TYPE_VALUES = {
    "int8": [-128, 127, -1, 5],
    "uint8": [0, 255, 1, 128],
    "int16": [-32768, 32767, -300, 7],
    "uint16": [0, 65535, 300, 9],
    "int32": [-2**31, 2**31 - 1, -70000, 11],
    "uint32": [0, 2**32 - 1, 70000, 13],
    "float32": [float(np.float32(0.1)), float(np.float32(-3.4e38)), float(np.float32(1e-30)), 0.5],
    "float64": [0.1, -1.7976931348623157e308, 5e-324, np.pi],
}


def every_type_attributes() -> dict:
    vertex = [{"name": f"p_{t}", "components": [f"p_{t}"], "type": t,
               "role": "generic" if t.startswith("float") else "label",
               "values": np.array(values, dtype=np.float64).reshape(4, 1)} for t, values in TYPE_VALUES.items()]
    vertex.append({"name": "color", "components": ["red", "green", "blue"], "type": "uint8", "role": "color",
                   "values": np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 20, 30]], dtype=np.float64)})
    face = [{"name": f"q_{t}", "components": [f"q_{t}"], "type": t,
             "role": "generic" if t.startswith("float") else "label",
             "values": np.array(values[::-1], dtype=np.float64).reshape(4, 1)} for t, values in TYPE_VALUES.items()]
    return {"vertex": vertex, "face": face}


def assert_channels_equal(written: list, read: list):
    assert [c["name"] for c in read] == [c["name"] for c in written]
    for w, r in zip(written, read):
        for key in ("components", "type", "role"):
            assert r[key] == w[key], (w["name"], key)
        assert r["values"].dtype == np.float64 and r["values"].shape == w["values"].shape, w["name"]
        assert r["values"].tobytes() == w["values"].tobytes(), w["name"]  # bit for bit


def read_spot():
    return vertexflow.read_mesh(DATA / "spot.obj", attributes=True, keep_faces=True)


def test_read_mesh_returns_spots_texture_coordinates_as_a_corner_channel():
    V, F, attributes = read_spot()
    assert set(attributes) == {"vertex", "corner", "face", "materials", "groups", "objects", "material_libraries"}
    assert [c["name"] for c in attributes["corner"]] == ["uv"]
    uv = attributes["corner"][0]
    assert uv["role"] == "texcoord" and uv["type"] == "float64" and len(uv["components"]) == 2
    assert uv["values"].shape == (3225, 2) and uv["values"].dtype == np.float64
    assert uv["corners"].shape == F.shape and uv["corners"].dtype == np.int32
    assert uv["corners"].min() >= 0 and uv["corners"].max() == 3224
    # The seams give some vertices more than one row.
    rows_per_vertex = {}
    for f in range(F.shape[0]):
        for k in range(3):
            rows_per_vertex.setdefault(F[f, k], set()).add(uv["corners"][f, k])
    assert max(len(rows) for rows in rows_per_vertex.values()) > 1


def test_read_mesh_returns_comments_then_attributes():
    result = vertexflow.read_mesh(DATA / "spot.obj", comments=True, attributes=True)
    assert len(result) == 4 and isinstance(result[2], list) and isinstance(result[3], dict)
    assert len(vertexflow.read_mesh(DATA / "spot.obj")) == 2
    assert len(vertexflow.read_mesh(DATA / "spot.obj", keep_faces=True)) == 2


def test_keep_faces_keeps_the_files_face_list(tmp_path):
    path = tmp_path / "messy.obj"
    # A duplicate face (the first, reversed) and an unreferenced vertex (5).
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 5 5 5\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 3 1\n")
    V, F = vertexflow.read_mesh(path)
    assert V.shape == (4, 3) and F.shape == (4, 3)
    V, F = vertexflow.read_mesh(path, keep_faces=True)
    assert V.shape == (5, 3) and F.shape == (5, 3)
    assert F[4].tolist() == [1, 2, 0]


@pytest.mark.parametrize("ascii", [False, True])
def test_every_scalar_type_round_trips_value_for_value(tmp_path, ascii):
    attributes = every_type_attributes()
    path = tmp_path / "types.ply"
    vertexflow.write_mesh(path, V_TET, F_TET, attributes=attributes, ascii=ascii)
    V, F, read = vertexflow.read_mesh(path, attributes=True, keep_faces=True)
    assert V.tobytes() == V_TET.tobytes() and np.array_equal(F, F_TET)
    assert_channels_equal(attributes["vertex"], read["vertex"])
    assert_channels_equal(attributes["face"], read["face"])
    assert read["corner"] == [] and read["materials"] == []


def test_spots_attributes_round_trip_through_obj(tmp_path):
    V, F, attributes = read_spot()
    vertexflow.write_mesh(tmp_path / "spot.obj", V, F, attributes=attributes)
    V2, F2, again = vertexflow.read_mesh(tmp_path / "spot.obj", attributes=True, keep_faces=True)
    assert V2.tobytes() == V.tobytes() and np.array_equal(F2, F)
    assert_channels_equal(attributes["corner"], again["corner"])
    assert np.array_equal(again["corner"][0]["corners"], attributes["corner"][0]["corners"])
    # Writing the dict read back gives the same bytes.
    vertexflow.write_mesh(tmp_path / "again.obj", V2, F2, attributes=again)
    assert (tmp_path / "again.obj").read_bytes() == (tmp_path / "spot.obj").read_bytes()


def test_a_channel_may_leave_out_components_type_and_role(tmp_path):
    path = tmp_path / "quality.ply"
    vertexflow.write_mesh(path, V_TET, F_TET, attributes={"vertex": [{"name": "quality", "values": np.arange(4.0)}]})
    _, _, read = vertexflow.read_mesh(path, attributes=True)
    (channel,) = read["vertex"]
    assert channel["name"] == "quality" and channel["components"] == ["quality"]
    assert channel["type"] == "float64" and channel["role"] == "generic"
    assert channel["values"].tolist() == [[0.0], [1.0], [2.0], [3.0]]


def test_enhance_resamples_the_uvs_of_moved_vertices_and_keeps_the_face_list():
    V, F, attributes = read_spot()
    uv = attributes["corner"][0]
    V_out, out, report = vertexflow.enhance(V, F, attributes=attributes, threads=1)
    assert "attributes" in report and "face_list" in report
    assert len(out["corner"]) == 1
    uv_out = out["corner"][0]
    assert {k: uv_out[k] for k in ("name", "components", "type", "role")} == \
        {k: uv[k] for k in ("name", "components", "type", "role")}
    # The face list, and so which row each corner uses, is the input's.
    assert uv_out["values"].shape == uv["values"].shape
    assert np.array_equal(uv_out["corners"], uv["corners"])
    # The rows that changed are rows of moved vertices, and the moved vertices' rows changed.
    moved = np.abs(V_out - V).max(axis=1) > 0
    changed_rows = np.flatnonzero(np.abs(uv_out["values"] - uv["values"]).max(axis=1) > 0)
    rows_of_moved = np.unique(uv["corners"][moved[F]])
    assert moved.sum() > 100 and len(changed_rows) > 100
    assert np.isin(changed_rows, rows_of_moved).all()
    # Re-sampled in place (interpolated in their charts): small steps, within the input's range.
    assert (uv_out["values"].min(axis=0) >= uv["values"].min(axis=0)).all()
    assert (uv_out["values"].max(axis=0) <= uv["values"].max(axis=0)).all()
    assert np.abs(uv_out["values"] - uv["values"]).max() < 0.05
    # Without attributes the result is (V_out, report); the input dict is not changed.
    assert len(vertexflow.enhance(V, F, threads=1)) == 2
    assert np.array_equal(attributes["corner"][0]["values"], read_spot()[2]["corner"][0]["values"])


def test_enhance_with_attributes_and_edge_flips_returns_the_faces_too():
    V, F, attributes = read_spot()
    V_out, F_out, out, report = vertexflow.enhance(V, F, attributes=attributes, edge_flips=True, threads=1)
    assert F_out.shape == F.shape and out["corner"][0]["corners"].shape == F.shape
    assert report["edge_flips"]


def bad(mutate):
    attributes = every_type_attributes()
    mutate(attributes)
    return attributes


def corner_uv(rows=3, corners=None):
    return {"name": "uv", "components": ["s", "t"], "type": "float32", "role": "texcoord",
            "values": np.zeros((rows, 2)), "corners": np.zeros((4, 3), dtype=np.int32) if corners is None else corners}


BAD = {
    "wrong row count": (lambda a: a["vertex"][0].update(values=np.zeros((3, 1))),
                        "vertex channel 'p_int8' has 3 rows for 4 vertices"),
    "wrong face row count": (lambda a: a["face"][2].update(values=np.zeros((5, 1))),
                             "face channel 'q_int16' has 5 rows for 4 faces"),
    "unknown role": (lambda a: a["vertex"][1].update(role="colour"),
                     "attributes['vertex'][1]['role']: 'colour' is not one of generic, color, texcoord"),
    "unknown type": (lambda a: a["face"][0].update(type="float16"),
                     "attributes['face'][0]['type']: 'float16' is not one of int8, uint8"),
    "unknown key": (lambda a: a.update(colors=[]), "attributes: unknown key 'colors'"),
    "unknown channel key": (lambda a: a["vertex"][0].update(kind="x"), "attributes['vertex'][0]: unknown key 'kind'"),
    "missing values": (lambda a: a["vertex"][0].pop("values"), "attributes['vertex'][0]['values'] is missing"),
    "missing name": (lambda a: a["face"][1].pop("name"), "attributes['face'][1]['name'] is missing"),
    "not a dict": (lambda a: a["vertex"].append("uv"), "attributes['vertex'][9] must be a dict, got str"),
    "value out of type": (lambda a: a["vertex"][1]["values"].__setitem__((0, 0), 256),
                          "attributes['vertex'][1]['values'] has 256.0 (row 0), not an integer that uint8 holds"),
    "fraction in an integer type": (lambda a: a["vertex"][4]["values"].__setitem__((2, 0), 0.5),
                                    "attributes['vertex'][4]['values'] has 0.5 (row 2), not an integer"),
    "components for the columns": (lambda a: a["vertex"][8].update(components=["red", "green"]),
                                   "attributes['vertex'][8]['components'] names 2 components for 3 columns"),
    "no components for columns": (lambda a: a["vertex"][8].pop("components"),
                                  "attributes['vertex'][8]['components'] is missing (needed for 3 columns)"),
    "corner out of its table": (lambda a: a.update(corner=[corner_uv(corners=np.full((4, 3), 3))]),
                                "attributes['corner'][0]['corners'] has 3 (row 0) outside -1..2"),
    "corners per face": (lambda a: a.update(corner=[corner_uv(corners=np.zeros((3, 3), dtype=np.int32))]),
                         "attributes['corner'][0]['corners'] must have shape (4, 3)"),
    "missing corners": (lambda a: a.update(corner=[{k: v for k, v in corner_uv().items() if k != "corners"}]),
                        "attributes['corner'][0]['corners'] is missing"),
    "corners on a vertex channel": (lambda a: a["vertex"][0].update(corners=np.zeros((4, 3))),
                                    "attributes['vertex'][0]: unknown key 'corners'"),
    "label past its names": (lambda a: a.update(materials=["red"], face=[
        {"name": "material", "type": "int32", "role": "label", "values": np.array([0, 1, 0, -1])}]),
        "face channel 'material' has a label outside -1..0"),
    "names not str": (lambda a: a.update(groups=[1, 2]), "attributes['groups'] must be a sequence of str"),
    "channels not a list": (lambda a: a.update(face={"name": "x"}), "attributes['face'] must be a list"),
}


@pytest.mark.parametrize("case", BAD)
def test_a_bad_dict_raises_value_error_naming_the_problem(tmp_path, case):
    mutate, message = BAD[case]
    attributes = bad(mutate)
    with pytest.raises(ValueError, match=re.escape(message)):
        vertexflow.write_mesh(tmp_path / "bad.ply", V_TET, F_TET, attributes=attributes)
    assert not (tmp_path / "bad.ply").exists()
    with pytest.raises(ValueError, match=re.escape(message)):
        vertexflow.enhance(V_TET, F_TET, attributes=attributes)


def test_attributes_must_be_a_dict():
    with pytest.raises(ValueError, match=r"^attributes must be a dict, got list"):
        vertexflow.write_mesh("never.ply", V_TET, F_TET, attributes=[])


def test_write_mesh_names_what_the_format_cannot_hold(tmp_path):
    V, F, attributes = vertexflow.read_mesh(DATA / "spot.obj", attributes=True)
    with pytest.warns(UserWarning, match=r"STL cannot hold, so it does not get: corner uv"):
        vertexflow.write_mesh(tmp_path / "spot.stl", V, F, attributes=attributes)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # OBJ holds spot's texture coordinates: no warning
        vertexflow.write_mesh(tmp_path / "spot.obj", V, F, attributes=attributes)
