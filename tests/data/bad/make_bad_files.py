#!/usr/bin/env python3
"""Writes the malformed mesh files in this directory (tests/data/bad/).

Every file here must make vertexflow::read_mesh throw IoError with a one-line message that
starts with the file's path; tests/io/test_bad_input.cpp reads every file in the directory and
holds the message fragment expected for each. The output is deterministic (fixed seeds, gzip
mtime 0), and the generated files are committed, so the corpus stays the same even if this
script changes; re-run it after adding a case:

    python3 tests/data/bad/make_bad_files.py

Files found by fuzzing are copied here by hand (named fuzz_*) and are not generated.
"""
import gzip
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

# A unit cube: 8 vertices, 6 quads.
CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
TRI_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def write(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def gz(data):
    if isinstance(data, str):
        data = data.encode()
    return gzip.compress(data, compresslevel=9, mtime=0)


def pad_comments(header_lines, size=1000):
    """Inserts comment lines after 'format' until the header is about `size` bytes."""
    lines = list(header_lines)
    while len("\n".join(lines)) < size:
        lines.insert(2, "comment padding the file to about one kilobyte")
    return lines


# --- PLY ---------------------------------------------------------------------------------

def ply_header(fmt, nv, nf, vertex_props=("float x", "float y", "float z"),
               face_prop="list uchar int vertex_indices", extra=()):
    lines = ["ply", f"format {fmt} 1.0", f"element vertex {nv}"]
    lines += [f"property {p}" for p in vertex_props]
    lines += [f"element face {nf}", f"property {face_prop}"]
    lines += list(extra)
    lines.append("end_header")
    return lines


def ply_binary_cube(big_endian):
    e = ">" if big_endian else "<"
    fmt = "binary_big_endian" if big_endian else "binary_little_endian"
    header = ("\n".join(ply_header(fmt, 8, 6)) + "\n").encode()
    vertices = b"".join(struct.pack(e + "fff", *v) for v in CUBE_V)
    faces = b"".join(struct.pack(e + "B4i", 4, *f) for f in CUBE_F)
    return header, vertices, faces  # 96 bytes of vertices, 6 * 17 bytes of faces


def ply_ascii(header_lines, body_lines):
    return "\n".join(header_lines) + "\n" + "\n".join(body_lines) + "\n"


TRI_BODY = ["0 0 0", "1 0 0", "0 1 0", "3 0 1 2"]


def make_ply():
    for big, tag in ((False, "le"), (True, "be")):
        header, vertices, faces = ply_binary_cube(big)
        # Cut after 5 of 8 vertices: the header's vertex count no longer fits.
        write(f"ply_{tag}_truncated_in_vertices.ply", header + vertices[:60])
        # Cut one byte short of the vertex section: passes the count check, fails mid-value.
        write(f"ply_{tag}_truncated_in_last_vertex.ply", header + vertices[:-1])
    header, vertices, faces = ply_binary_cube(False)
    # Cut one byte short inside the 4th face's index list.
    write("ply_le_truncated_in_faces.ply", header + vertices + faces[:3 * 17 + 16])
    # Cut exactly after 3 of 6 faces: the next list count is missing.
    write("ply_le_truncated_at_face_boundary.ply", header + vertices + faces[:3 * 17])
    header, vertices, faces = ply_binary_cube(True)
    # Cut in the middle of the 4th face: its list count (4) exceeds what is left.
    write("ply_be_truncated_in_faces.ply", header + vertices + faces[:3 * 17 + 6])

    # Counts that a ~1 kB file cannot hold.
    write("ply_huge_face_count.ply", ply_ascii(pad_comments(ply_header("ascii", 3, 2000000000)), TRI_BODY))
    write("ply_huge_vertex_count.ply", ply_ascii(pad_comments(ply_header("ascii", 2000000000, 1)), TRI_BODY))
    tri_le = b"".join(struct.pack("<fff", *v) for v in TRI_V) + struct.pack("<B3i", 3, 0, 1, 2)
    tri_be = b"".join(struct.pack(">fff", *v) for v in TRI_V) + struct.pack(">B3i", 3, 0, 1, 2)
    write("ply_le_huge_face_count.ply",
          ("\n".join(pad_comments(ply_header("binary_little_endian", 3, 2000000000))) + "\n").encode() + tri_le)
    write("ply_be_huge_vertex_count.ply",
          ("\n".join(pad_comments(ply_header("binary_big_endian", 2000000000, 1))) + "\n").encode() + tri_be)
    write("ply_count_overflow.ply", ply_ascii(ply_header("ascii", 3, "99999999999999999999"), TRI_BODY))
    write("ply_negative_count.ply", ply_ascii(ply_header("ascii", -3, 1), TRI_BODY))

    # Header structure.
    write("ply_no_end_header.ply", "\n".join(ply_header("ascii", 3, 1)[:-1]) + "\n" + "\n".join(TRI_BODY) + "\n")
    write("ply_unknown_format.ply", ply_ascii(ply_header("binary_middle_endian", 3, 1), TRI_BODY))
    write("ply_no_format.ply", ply_ascii([l for l in ply_header("ascii", 3, 1) if not l.startswith("format")], TRI_BODY))
    write("ply_unknown_type.ply",
          ply_ascii(ply_header("ascii", 3, 1, vertex_props=("float128 x", "float y", "float z")), TRI_BODY))
    write("ply_unknown_keyword.ply",
          ply_ascii([l.replace("element vertex", "elemnt vertex") for l in ply_header("ascii", 3, 1)], TRI_BODY))
    write("ply_property_before_element.ply",
          ply_ascii(["ply", "format ascii 1.0", "property float w"] + ply_header("ascii", 3, 1)[2:], TRI_BODY))
    write("ply_not_ply.ply", ply_ascii(["PLY"] + ply_header("ascii", 3, 1)[1:], TRI_BODY))
    write("ply_no_face_element.ply",
          ply_ascii(["ply", "format ascii 1.0", "element vertex 3", "property float x", "property float y",
                     "property float z", "end_header"], TRI_BODY[:3]))
    write("ply_no_vertex_element.ply",
          ply_ascii(["ply", "format ascii 1.0", "element face 1", "property list uchar int vertex_indices",
                     "end_header"], TRI_BODY[3:]))
    write("ply_missing_z.ply",
          ply_ascii(ply_header("ascii", 3, 1, vertex_props=("float x", "float y", "float w")), TRI_BODY))
    write("ply_float_indices.ply",
          ply_ascii(ply_header("ascii", 3, 1, face_prop="list uchar float vertex_indices"), TRI_BODY))
    write("ply_float_list_count.ply",
          ply_ascii(ply_header("ascii", 3, 1, face_prop="list float int vertex_indices"), TRI_BODY))
    write("ply_no_vertex_indices.ply",
          ply_ascii(ply_header("ascii", 3, 1, face_prop="list uchar int corner_list"), TRI_BODY))
    write("ply_header_only.ply", ply_ascii(ply_header("ascii", 0, 0), []))
    # Two vertex elements of different sizes, the first with colours: the second must not be
    # read over the first (the colour array would be shorter than the vertex array).
    write("ply_duplicate_vertex_element.ply",
          ply_ascii(["ply", "format ascii 1.0", "element vertex 1", "property float x", "property float y",
                     "property float z", "property uchar red", "property uchar green", "property uchar blue",
                     "property float quality",
                     "element vertex 3", "property float x", "property float y", "property float z",
                     "element face 1", "property list uchar int vertex_indices", "end_header"],
                    ["0 0 0 255 0 0 1"] + TRI_BODY))

    # List counts that lie.
    def tri_with_list(count_type, count_fmt, count):
        return (("\n".join(ply_header("binary_little_endian", 3, 1,
                                      face_prop=f"list {count_type} int vertex_indices")) + "\n").encode()
                + b"".join(struct.pack("<fff", *v) for v in TRI_V)
                + struct.pack("<" + count_fmt, count) + struct.pack("<3i", 0, 1, 2))
    write("ply_list_count_255.ply", tri_with_list("uchar", "B", 255))
    write("ply_list_count_2pow31.ply", tri_with_list("uint", "I", 2 ** 31))
    write("ply_list_count_negative.ply", tri_with_list("int", "i", -1))

    # Bad values.
    write("ply_ascii_not_a_number.ply", ply_ascii(ply_header("ascii", 3, 1), ["0 0 0", "1 0 zero", "0 1 0", "3 0 1 2"]))
    write("ply_ascii_float_index.ply", ply_ascii(ply_header("ascii", 3, 1), TRI_BODY[:3] + ["3 0 1.5 2"]))
    write("ply_ascii_index_out_of_range.ply", ply_ascii(ply_header("ascii", 3, 1), TRI_BODY[:3] + ["3 0 1 7"]))
    write("ply_ascii_truncated.ply",
          ply_ascii(ply_header("ascii", 8, 6), ["0.000000 0.000000 0.000000"] * 5))
    write("ply_ascii_face_two_vertices.ply", ply_ascii(ply_header("ascii", 3, 1), TRI_BODY[:3] + ["2 0 1"]))
    write("ply_ascii_nan.ply", ply_ascii(ply_header("ascii", 3, 1), ["nan 0 0"] + TRI_BODY[1:]))
    write("ply_ascii_1e999.ply", ply_ascii(ply_header("ascii", 3, 1), ["0 0 0", "1e999 0 0"] + TRI_BODY[2:]))
    # Extra values on a line are ignored with a warning, but they must be numbers; missing ones
    # are an error on their line.
    write("ply_ascii_extra_text.ply", ply_ascii(ply_header("ascii", 3, 1), ["0 0 0", "1 0 0 normal"] + TRI_BODY[2:]))
    write("ply_ascii_face_too_few_indices.ply", ply_ascii(ply_header("ascii", 3, 1), TRI_BODY[:3] + ["4 0 1 2"]))
    write("ply_ascii_all_degenerate.ply", ply_ascii(ply_header("ascii", 3, 2), TRI_BODY[:3] + ["3 0 0 1", "3 2 2 2"]))
    header = ("\n".join(ply_header("binary_little_endian", 3, 1)) + "\n").encode()
    write("ply_le_inf.ply", header + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, float("inf"), 0)
          + struct.pack("<B3i", 3, 0, 1, 2))
    write("ply_le_negative_index.ply", header + b"".join(struct.pack("<fff", *v) for v in TRI_V)
          + struct.pack("<B3i", 3, 0, -1, 2))
    header_u = ("\n".join(ply_header("binary_little_endian", 3, 1, face_prop="list uchar uint vertex_indices"))
                + "\n").encode()
    write("ply_le_uint_index_too_large.ply", header_u + b"".join(struct.pack("<fff", *v) for v in TRI_V)
          + struct.pack("<B3I", 3, 0, 1, 0xFFFFFFFF))


# --- OFF ---------------------------------------------------------------------------------

def off_ascii(nv, nf, vertex_lines, face_lines, keyword="OFF"):
    return "\n".join([keyword, f"{nv} {nf} 0"] + vertex_lines + face_lines) + "\n"


TET_V = ["0 0 0", "1 0 0", "0 1 0", "0 0 1"]
TET_F = ["3 0 2 1", "3 0 1 3", "3 1 2 3", "3 0 3 2"]


def off_binary(nv, nf, body, big_endian=True):
    e = ">" if big_endian else "<"
    return b"OFF BINARY\n" + struct.pack(e + "3i", nv, nf, 0) + body


def cube_binary_body():
    vertices = b"".join(struct.pack(">fff", *v) for v in CUBE_V)
    faces = b"".join(struct.pack(">5i", 4, *f) + struct.pack(">i", 0) for f in CUBE_F)
    return vertices, faces  # 96 + 6 * 24 bytes


def make_off():
    vertices, faces = cube_binary_body()
    write("off_binary_truncated_in_vertices.off", off_binary(8, 6, vertices[:50]))
    write("off_binary_truncated_in_faces.off", off_binary(8, 6, vertices + faces[:5 * 24 + 10]))
    write("off_binary_huge_counts.off", off_binary(2000000000, 2000000000, (vertices + faces) * 4))
    write("off_binary_negative_counts.off", off_binary(-1, 6, vertices + faces))
    write("off_binary_negative_index.off",
          off_binary(3, 1, b"".join(struct.pack(">fff", *v) for v in TRI_V) + struct.pack(">5i", 3, 0, -1, 2, 0)))
    write("off_binary_face_count_lies.off",
          off_binary(3, 1, b"".join(struct.pack(">fff", *v) for v in TRI_V) + struct.pack(">5i", 1000000, 0, 1, 2, 0)))

    filler = ["# padding the file to about one kilobyte"] * 24
    write("off_huge_counts.off", "\n".join(["OFF", "2000000000 2000000000 0"] + filler + TET_V + TET_F) + "\n")
    write("off_huge_vertex_count.off", "\n".join(["OFF", "2000000000 4 0"] + filler + TET_V + TET_F) + "\n")
    write("off_negative_counts.off", off_ascii(-3, 1, TET_V, TET_F))
    write("off_negative_face_count.off", off_ascii(4, -4, TET_V, TET_F))
    write("off_index_out_of_range.off", off_ascii(4, 4, TET_V, TET_F[:3] + ["3 0 3 5"]))
    write("off_negative_index.off", off_ascii(4, 4, TET_V, ["3 0 -1 2"] + TET_F[1:]))
    write("off_not_off.off", off_ascii(4, 4, TET_V, TET_F, keyword="OFX"))
    write("off_4off.off", off_ascii(4, 4, TET_V, TET_F, keyword="4OFF"))
    write("off_face_count_lies.off", off_ascii(4, 4, TET_V, ["1000 0 1 2"] + TET_F[1:]))
    write("off_not_a_number.off", off_ascii(4, 4, ["0 0 0", "1 0 x"] + TET_V[2:], TET_F))
    write("off_missing_counts.off", "OFF\n")
    write("off_nan.off", off_ascii(4, 4, ["0 nan 0"] + TET_V[1:], TET_F))
    write("off_1e999.off", off_ascii(4, 4, TET_V[:3] + ["0 0 -1e999"], TET_F))
    # (padded so the size check on the counts passes and the short face itself is reported)
    write("off_face_two_vertices.off", off_ascii(4, 4, TET_V, TET_F[:3] + ["2 0 1        "]))
    write("off_truncated_ascii.off", off_ascii(4, 4, TET_V, TET_F[:2]))


# --- OBJ ---------------------------------------------------------------------------------

OBJ_TRI = ["# a triangle", "v 0 0 0", "v 1 0 0", "v 0 1 0"]


def obj(lines):
    return "\n".join(lines) + "\n"


def make_obj():
    write("obj_index_zero.obj", obj(OBJ_TRI + ["f 0 1 2"]))
    write("obj_index_out_of_range.obj", obj(OBJ_TRI + ["f 1 2 9"]))
    write("obj_negative_index_beyond_start.obj", obj(OBJ_TRI + ["f -1 -2 -4"]))
    write("obj_index_too_large.obj", obj(OBJ_TRI + ["f 1 2 3000000000"]))
    write("obj_index_overflow.obj", obj(OBJ_TRI + ["f 1 2 99999999999999999999"]))
    # Found by fuzz_read_obj (UBSan): 2^31 is a valid Index once 0-based; the message added the
    # base back in 32 bits.
    write("obj_index_2_to_the_31.obj", obj(OBJ_TRI + ["f 1 2 2147483648"]))
    # Issue 12: every vertex at one point made `enhance` loop forever.
    write("obj_all_vertices_at_one_point.obj",
          obj(["v 1 1 1", "v 1 1 1", "v 1 1 1", "v 1 1 1", "f 1 3 2", "f 1 2 4", "f 1 4 3", "f 2 3 4"]))
    write("obj_face_garbage.obj", obj(OBJ_TRI + ["f 1 2 three"]))
    write("obj_garbage_number.obj", obj(["v 0 0 0", "v 1.0abc 0 0", "v 0 1 0", "f 1 2 3"]))
    write("obj_nan.obj", obj(["v 0 0 0", "v nan 0 0", "v 0 1 0", "f 1 2 3"]))
    write("obj_inf.obj", obj(["v 0 0 0", "v 1 0 0", "v 0 inf 0", "f 1 2 3"]))
    write("obj_1e999.obj", obj(["v 0 0 0", "v 1 0 0", "v 0 1 1e999", "f 1 2 3"]))
    write("obj_vertex_two_coords.obj", obj(["v 0 0 0", "v 1 0", "v 0 1 0", "f 1 2 3"]))
    write("obj_face_two_vertices.obj", obj(OBJ_TRI + ["f 1 2"]))
    write("obj_no_faces.obj", obj(OBJ_TRI))
    # Line continuation: errors name the statement's first line; a backslash with text after it
    # on its line continues nothing; a face continued to the end of the file has two vertices.
    write("obj_continued_face_garbage.obj", obj(OBJ_TRI + ["f 1 \\", "2 \\", "three"]))
    write("obj_backslash_inside_line.obj", obj(OBJ_TRI + ["f 1 2 \\ 3"]))
    write("obj_continued_to_the_end.obj", obj(OBJ_TRI + ["f 1 2 \\"] + ["\\"] * 1000))
    # The same with 8 MB of continuation lines, about 8 kB compressed; the tests also read it
    # with a 1 MiB inflation limit and expect the limit to stop it.
    write("gz_obj_continued_line.obj.gz", gz(obj(OBJ_TRI + ["f 1 2 \\"]).encode() + b"\\\n" * (4 << 20)))
    write("obj_no_vertices.obj", obj(["# nothing but comments", "g group", "usemtl none"]))
    write("obj_all_degenerate.obj", obj(["v 0 0 0", "v 1 0 0", "v 2 0 0", "f 1 2 3"]))


# --- STL ---------------------------------------------------------------------------------

def stl_record(a, b, c):
    return struct.pack("<3f", 0, 0, 0) + struct.pack("<9f", *a, *b, *c) + struct.pack("<H", 0)


def stl_facet(corners):
    return (["  facet normal 0 0 1", "    outer loop"] + [f"      vertex {x} {y} {z}" for x, y, z in corners]
            + ["    endloop", "  endfacet"])


def make_stl():
    tri = stl_record(*TRI_V)
    write("stl_binary_count_lies.stl", b"binary".ljust(80, b" ") + struct.pack("<I", 1000000) + tri * 2)
    write("stl_binary_count_max.stl", b"binary".ljust(80, b" ") + struct.pack("<I", 0xFFFFFFFF) + tri * 2)
    write("stl_binary_too_short.stl", b"\0" * 40)
    write("stl_binary_zero_triangles.stl", b"binary".ljust(80, b" ") + struct.pack("<I", 0))
    write("stl_binary_nan.stl", b"binary".ljust(80, b" ") + struct.pack("<I", 1)
          + stl_record((0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)))
    write("stl_binary_degenerate.stl", b"binary".ljust(80, b" ") + struct.pack("<I", 1)
          + stl_record((0, 0, 0), (1, 0, 0), (2, 0, 0)))
    # A binary file whose comment starts with "solid", cut short: no longer matches its declared
    # size, so it is taken for ASCII STL and fails there.
    write("stl_binary_solid_truncated.stl", b"solid but binary".ljust(80, b" ") + struct.pack("<I", 2) + tri + tri[:20])
    facet = stl_facet(TRI_V)
    write("stl_ascii_truncated_in_facet.stl", "\n".join(["solid t"] + facet + facet[:4]) + "\n")
    write("stl_ascii_truncated_in_vertex.stl", "\n".join(["solid t"] + facet + facet[:4] + ["      vertex 0 1"]))
    write("stl_ascii_four_vertices.stl",
          "\n".join(["solid t"] + stl_facet(TRI_V + [(1, 1, 0)]) + ["endsolid t"]) + "\n")
    write("stl_ascii_two_vertices.stl", "\n".join(["solid t"] + stl_facet(TRI_V[:2]) + ["endsolid t"]) + "\n")
    write("stl_ascii_garbage.stl",
          "\n".join(["solid t"] + [l.replace("vertex 1 0 0", "vertex 1 0 abc") for l in facet] + ["endsolid t"]) + "\n")
    write("stl_ascii_unexpected_keyword.stl",
          "\n".join(["solid t"] + [l.replace("endloop", "endlop") for l in facet] + ["endsolid t"]) + "\n")


# --- everything else ---------------------------------------------------------------------

def make_misc():
    for ext in ("obj", "ply", "off", "stl"):
        write(f"empty.{ext}", b"")
    write("empty.ply.gz", gz(b""))
    rng = random.Random(20240521)
    for ext in ("obj", "ply", "off", "stl"):
        data = bytes(rng.getrandbits(8) for _ in range(2048))
        assert data[:2] != b"\x1f\x8b"
        write(f"random.{ext}", data)

    ply = ply_ascii(ply_header("ascii", 8, 6),
                    [" ".join(map(str, v)) for v in CUBE_V] + ["4 " + " ".join(map(str, f)) for f in CUBE_F])
    packed = gz(ply)
    write("gz_truncated.ply.gz", packed[: len(packed) * 2 // 3])
    write("gz_header_only.ply.gz", packed[:10])
    corrupt = bytearray(packed)
    for i in range(12, 40):
        corrupt[i] ^= 0x5A
    write("gz_corrupt.ply.gz", bytes(corrupt))
    bad_crc = bytearray(packed)
    bad_crc[-8] ^= 0xFF  # CRC-32 of the member (the last 8 bytes are CRC-32 and size)
    write("gz_bad_crc.ply.gz", bytes(bad_crc))
    write("gz_second_member_truncated.ply.gz", packed + packed[: len(packed) // 2])
    write("gz_huge_face_count.ply.gz", gz(ply_ascii(pad_comments(ply_header("ascii", 3, 2000000000)), TRI_BODY)))
    # A small "bomb": 8 MB of blank lines after a PLY magic line, about 8 kB compressed.
    # Read with the default limit it fails for lack of end_header; the tests also read it with
    # a 1 MB max_decompressed_bytes and expect the limit to stop it.
    write("gz_bomb.ply.gz", gz(b"ply\nformat ascii 1.0\n" + b"\n" * (8 << 20)))

    write("unknown.xyz", off_ascii(4, 4, TET_V, TET_F))
    write("no_extension", off_ascii(4, 4, TET_V, TET_F))
    write("only.gz", gz(off_ascii(4, 4, TET_V, TET_F)))


def main():
    make_ply()
    make_off()
    make_obj()
    make_stl()
    make_misc()


if __name__ == "__main__":
    main()
