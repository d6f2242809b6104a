#!/usr/bin/env python3
"""Writes small valid meshes in every supported encoding to tests/fuzz/seeds/ (the fuzzers'
seed corpus, together with tests/data/bad and the small meshes in data/).

Each seed exercises a different reader path: quads and a non-convex polygon (triangulation),
PLY colours, extra scalar and list properties and an extra element, OBJ v/t/n corners and
negative indices, OFF variants (COFF, NOFF, STOFF, binary big- and little-endian), STL ASCII and
binary (including a binary file whose header starts with "solid"), and gzip.

Run: python3 tests/fuzz/make_seeds.py   (deterministic; the output is committed)
"""
import gzip
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "seeds")

# A cube (8 vertices, 6 quads) and an L-shaped hexagon (non-convex, needs the CDT path).
CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
L_V = [(0, 0, 0), (2, 0, 0), (2, 1, 0), (1, 1, 0), (1, 2, 0), (0, 2, 0)]
L_F = [(0, 1, 2, 3, 4, 5)]
TET_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TET_F = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]


def write(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(data)


def gz(data):
    if isinstance(data, str):
        data = data.encode()
    return gzip.compress(data, compresslevel=9, mtime=0)


def ply_ascii(verts, faces):
    out = ["ply", "format ascii 1.0", "comment seed", "obj_info generated",
           f"element vertex {len(verts)}", "property float x", "property float y", "property float z",
           "property uchar red", "property uchar green", "property uchar blue", "property uchar alpha",
           "property float quality", "property list uchar int vertex_extra",
           f"element face {len(faces)}", "property list uchar int vertex_indices", "property uchar flags",
           "element edge 1", "property int vertex1", "property int vertex2", "end_header"]
    for i, (x, y, z) in enumerate(verts):
        out.append(f"{x} {y} {z} {10 * i % 256} 20 30 255 {i * 0.5} 2 {i} {i}")
    for f in faces:
        out.append(f"{len(f)} " + " ".join(map(str, f)) + " 7")
    out.append("0 1")
    return "\n".join(out) + "\n"


def ply_binary(verts, faces, big_endian, double=False, index_type="int", count_type="uchar"):
    e = ">" if big_endian else "<"
    fmt_name = "binary_big_endian" if big_endian else "binary_little_endian"
    ctype = "double" if double else "float"
    header = ["ply", f"format {fmt_name} 1.0", f"element vertex {len(verts)}",
              f"property {ctype} x", f"property {ctype} y", f"property {ctype} z", "property short tag",
              f"element face {len(faces)}", f"property list {count_type} {index_type} vertex_indices",
              "end_header"]
    body = b""
    for i, v in enumerate(verts):
        body += struct.pack(e + ("ddd" if double else "fff"), *v) + struct.pack(e + "h", -i)
    cfmt = {"uchar": "B", "ushort": "H", "int": "i", "uint": "I"}[count_type]
    ifmt = {"int": "i", "uint": "I", "ushort": "H", "uchar": "B"}[index_type]
    for f in faces:
        body += struct.pack(e + cfmt, len(f)) + struct.pack(e + ifmt * len(f), *f)
    return ("\n".join(header) + "\n").encode() + body


def obj(verts, faces, negative=False):
    out = ["# seed", "mtllib x.mtl", "o thing"]
    for v in verts:
        out.append("v " + " ".join(f"{c:g}" for c in v))
    out.append("vt 0 0")
    out.append("vn 0 0 1")
    out.append("g group")
    out.append("usemtl m")
    n = len(verts)
    for k, f in enumerate(faces):
        if negative:
            out.append("f " + " ".join(str(i - n) for i in f))
        elif k % 2:
            out.append("f " + " ".join(f"{i + 1}/1/1" for i in f))
        else:
            out.append("f " + " ".join(f"{i + 1}//1" for i in f))
    out.append("l 1 2")
    return "\r\n".join(out) + "\r\n"


def off_ascii(verts, faces, keyword="OFF"):
    out = [keyword, "# comment", f"{len(verts)} {len(faces)} 0"]
    for v in verts:
        extra = ""
        if keyword.startswith("ST"):
            extra += " 0.5 0.5"
        if "C" in keyword:
            extra += " 1 0 0 1"
        if "N" in keyword:
            extra += " 0 0 1"
        out.append(" ".join(map(str, v)) + extra)
    for f in faces:
        out.append(f"{len(f)} " + " ".join(map(str, f)) + " 0.5 0.5 0.5")
    return "\n".join(out) + "\n"


def off_binary(verts, faces, big_endian, face_colors):
    e = ">" if big_endian else "<"
    body = struct.pack(e + "iii", len(verts), len(faces), 0)
    for v in verts:
        body += struct.pack(e + "fff", *v)
    for f in faces:
        body += struct.pack(e + "i", len(f)) + struct.pack(e + "i" * len(f), *f)
        if face_colors:
            body += struct.pack(e + "i", 0)
    return b"OFF BINARY\n" + body


def stl_triangles(verts, faces):
    tris = []
    for f in faces:
        for k in range(1, len(f) - 1):
            tris.append((verts[f[0]], verts[f[k]], verts[f[k + 1]]))
    return tris


def stl_ascii(verts, faces):
    out = ["solid seed"]
    for a, b, c in stl_triangles(verts, faces):
        out += ["  facet normal 0 0 0", "    outer loop"]
        out += [f"      vertex {p[0]:e} {p[1]:e} {p[2]:e}" for p in (a, b, c)]
        out += ["    endloop", "  endfacet"]
    out.append("endsolid seed")
    return "\n".join(out) + "\n"


def stl_binary(verts, faces, comment=b"binary seed"):
    tris = stl_triangles(verts, faces)
    data = comment.ljust(80, b" ") + struct.pack("<I", len(tris))
    for a, b, c in tris:
        data += struct.pack("<3f", 0, 0, 0) + struct.pack("<9f", *a, *b, *c) + struct.pack("<H", 0)
    return data


def main():
    os.makedirs(OUT, exist_ok=True)
    write("cube_ascii.ply", ply_ascii(CUBE_V, CUBE_F))
    write("lshape_ascii.ply", ply_ascii(L_V, L_F))
    write("cube_le.ply", ply_binary(CUBE_V, CUBE_F, big_endian=False))
    write("cube_be.ply", ply_binary(CUBE_V, CUBE_F, big_endian=True, double=True, index_type="uint"))
    write("tet_le_ushort.ply", ply_binary(TET_V, TET_F, big_endian=False, index_type="ushort", count_type="int"))
    write("cube_le.ply.gz", gz(ply_binary(CUBE_V, CUBE_F, big_endian=False)))
    write("cube.obj", obj(CUBE_V, CUBE_F))
    write("lshape_negative.obj", obj(L_V, L_F, negative=True))
    write("tet.obj.gz", gz(obj(TET_V, TET_F)))
    write("cube.off", off_ascii(CUBE_V, CUBE_F))
    write("lshape_stcnoff.off", off_ascii(L_V, L_F, "STCNOFF"))
    write("tet_coff.off", off_ascii(TET_V, TET_F, "COFF"))
    write("cube_binary_be.off", off_binary(CUBE_V, CUBE_F, big_endian=True, face_colors=True))
    write("cube_binary_le.off", off_binary(CUBE_V, CUBE_F, big_endian=False, face_colors=False))
    write("cube.off.gz", gz(off_ascii(CUBE_V, CUBE_F)))
    write("cube_ascii.stl", stl_ascii(CUBE_V, CUBE_F))
    write("cube_binary.stl", stl_binary(CUBE_V, CUBE_F))
    write("cube_binary_solid.stl", stl_binary(CUBE_V, CUBE_F, comment=b"solid but binary"))
    write("tet_ascii.stl.gz", gz(stl_ascii(TET_V, TET_F)))
    # Extreme but finite coordinates: the polygon normal and projection overflow or underflow.
    scaled = lambda s: [(x * s, y * s, z * s) for x, y, z in L_V]
    write("lshape_huge.obj", obj(scaled(1e300), L_F))
    write("lshape_tiny.obj", obj(scaled(1e-300), L_F))
    write("cube_huge.off", off_ascii([(x * 1e200, y * 1e200, z * 1e200) for x, y, z in CUBE_V], CUBE_F))


if __name__ == "__main__":
    main()
