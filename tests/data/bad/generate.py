#!/usr/bin/env python3
"""Regenerates the binary and programmatic cases of the malformed-input corpus.

    python3 tests/data/bad/generate.py        (from anywhere; writes next to this script)

The hand-written text cases (OBJ, ascii PLY, OFF, ascii STL, landmarks, targets, sphere
maps) are committed as they are; this script writes the cases that are binary (PLY, STL,
GLB), need base64 (glTF data URIs) or are meshes easier to compute than to type (genus 1
and 2). Its output is committed too, so the tests do not need Python; rerun it after
changing a case here and commit the result. Deterministic: no randomness, no timestamps.
Large inputs are not written here: bad_input_test.cpp generates them in a temporary folder.
"""
import base64
import json
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

# The octahedron every small case starts from (0-based faces, outward).
OCT_V = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
OCT_F = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]


def write(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


# ---- binary PLY ---------------------------------------------------------------------------

def binary_ply(V, F, endian="<", header_vertices=None, header_faces=None):
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    nv = len(V) if header_vertices is None else header_vertices
    nf = len(F) if header_faces is None else header_faces
    head = (f"ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\n"
            f"property float z\nelement face {nf}\nproperty list uchar int vertex_indices\nend_header\n")
    body = b"".join(struct.pack(endian + "3f", *v) for v in V)
    body += b"".join(struct.pack(endian + "B3i", 3, *f) for f in F)
    return head.encode() + body


def ply_cases():
    good = binary_ply(OCT_V, OCT_F)
    write("octahedron_binary.ply", good)
    # Shorter than declared: the last face loses 7 of its 13 bytes.
    write("ply_binary_le_truncated.ply", good[:-7])
    # Big endian, cut inside the vertex block (after 4 of 6 vertices and 2 bytes of the 5th).
    be = binary_ply(OCT_V, OCT_F, endian=">")
    header_end = be.index(b"end_header\n") + len(b"end_header\n")
    write("ply_binary_be_truncated.ply", be[:header_end + 4 * 12 + 2])
    # The header claims 4 billion vertices; the file holds 6. Must fail at once, without
    # allocating for the claimed count.
    write("ply_binary_huge_count.ply", binary_ply(OCT_V, OCT_F, header_vertices=4000000000))
    # The header claims one face more than the file holds.
    write("ply_binary_face_count_too_high.ply", binary_ply(OCT_V, OCT_F, header_faces=9))
    # A NaN coordinate in binary (the text readers see "nan"; here it is a bit pattern).
    nan_v = list(OCT_V)
    nan_v[3] = (0.0, float("nan"), 0.0)
    write("ply_binary_nan.ply", binary_ply(nan_v, OCT_F))
    # A list length of 255 corners in a face of a 13-byte record: runs off the end.
    bad = bytearray(good)
    bad[len(good) - 13] = 255
    write("ply_binary_bad_list_length.ply", bytes(bad))


# ---- binary STL ---------------------------------------------------------------------------

def binary_stl(tris, count=None):
    head = b"binary STL written by generate.py".ljust(80, b" ")
    n = len(tris) if count is None else count
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *a, *b, *c, 0) for a, b, c in tris)
    return head + struct.pack("<I", n) + body


def stl_cases():
    tris = [tuple(OCT_V[i] for i in f) for f in OCT_F]
    write("octahedron.stl", binary_stl(tris))
    # 8 triangles declared, 5 and a half present.
    write("stl_binary_truncated.stl", binary_stl(tris)[: 84 + 5 * 50 + 25])
    nan_tris = list(tris)
    nan_tris[2] = ((float("nan"), 0, 0), tris[2][1], tris[2][2])
    write("stl_binary_nan.stl", binary_stl(nan_tris))
    # Only the header, declaring 0 triangles: a valid file without faces.
    write("stl_binary_no_triangles.stl", binary_stl([]))


# ---- glTF / GLB ---------------------------------------------------------------------------

def gltf_doc(buffer_uri=None, byte_length=None, index_override=None, buffer_index=0):
    pos = b"".join(struct.pack("<3f", *v) for v in OCT_V)
    faces = [list(f) for f in OCT_F]
    if index_override is not None:
        faces[-1][-1] = index_override
    idx = b"".join(struct.pack("<3H", *f) for f in faces)
    data = pos + idx
    buf = {"byteLength": len(data) if byte_length is None else byte_length}
    if buffer_uri is not None:
        buf["uri"] = buffer_uri
    doc = {
        "asset": {"version": "2.0", "generator": "spherekit tests/data/bad/generate.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3",
             "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 24, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": buffer_index, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": buffer_index, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "buffers": [buf],
    }
    return doc, data


def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def dumps(doc):
    return json.dumps(doc, indent=1) + "\n"


def glb(doc, bin_data):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bin_data += b"\0" * (-len(bin_data) % 4)
    chunks = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(bin_data), 0x004E4942) + bin_data
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks


def gltf_cases():
    doc, data = gltf_doc()
    doc["buffers"][0]["uri"] = data_uri(data)
    write("octahedron.gltf", dumps(doc))
    # The buffer file the document names does not exist (it must stay absent from this folder).
    doc, _ = gltf_doc(buffer_uri="gltf_missing_buffer.bin")
    write("gltf_missing_buffer_file.gltf", dumps(doc))
    # The buffer is a device that never ends (/dev/zero): must be refused, not read forever.
    doc, _ = gltf_doc(buffer_uri="/dev/zero")
    write("gltf_buffer_device.gltf", dumps(doc))
    # The absent buffer file's name holds a newline (fuzzing finding: it broke the one-line
    # message).
    doc, _ = gltf_doc(buffer_uri="missing\nbuffer.bin")
    write("gltf_buffer_uri_newline.gltf", dumps(doc))
    # The buffer views refer to buffer 1; the document has only buffer 0.
    doc, data = gltf_doc(buffer_index=1)
    doc["buffers"][0]["uri"] = data_uri(data)
    write("gltf_missing_buffer_entry.gltf", dumps(doc))
    # byteLength claims more bytes than the data URI holds.
    doc, data = gltf_doc(byte_length=4096)
    doc["buffers"][0]["uri"] = data_uri(data)
    write("gltf_buffer_too_short.gltf", dumps(doc))
    # An index beyond the 6 positions.
    doc, data = gltf_doc(index_override=6)
    doc["buffers"][0]["uri"] = data_uri(data)
    write("gltf_index_out_of_range.gltf", dumps(doc))
    # JSON cut in the middle.
    doc, data = gltf_doc()
    doc["buffers"][0]["uri"] = data_uri(data)
    text = dumps(doc)
    write("gltf_invalid_json.gltf", text[: len(text) // 2])
    # GLB: valid, truncated (the header's length exceeds the file), bad magic.
    doc, data = gltf_doc()
    good = glb(doc, data)
    write("octahedron.glb", good)
    write("glb_truncated.glb", good[: len(good) - 40])
    write("glb_bad_magic.glb", b"glTX" + good[4:])


# ---- meshes of higher genus ---------------------------------------------------------------

def obj_text(V, F, comment):
    lines = ["# " + comment]
    lines += ["v %.17g %.17g %.17g" % v for v in V]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in F]
    return "\n".join(lines) + "\n"


def torus(n=8, m=6, R=1.0, r=0.35):
    import math
    V = []
    for i in range(n):
        for j in range(m):
            u, v = 2 * math.pi * i / n, 2 * math.pi * j / m
            V.append(((R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v)))
    F = []
    for i in range(n):
        for j in range(m):
            a, b = i * m + j, ((i + 1) % n) * m + j
            c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
            F += [(a, b, c), (a, c, d)]
    return V, F


def voxel_surface(cells):
    """Boundary of a union of unit cubes as outward triangles, vertices welded on the grid."""
    cells = set(cells)
    index, V, F = {}, [], []

    def vid(p):
        if p not in index:
            index[p] = len(V)
            V.append(p)
        return index[p]

    # For each axis and direction: the face's four corners, counter-clockwise from outside.
    faces = {
        (1, 0, 0): [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)],
        (-1, 0, 0): [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)],
        (0, 1, 0): [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)],
        (0, -1, 0): [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)],
        (0, 0, 1): [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
        (0, 0, -1): [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)],
    }
    for (x, y, z) in sorted(cells):
        for (dx, dy, dz), quad in faces.items():
            if (x + dx, y + dy, z + dz) in cells:
                continue
            q = [vid((x + a, y + b, z + c)) for a, b, c in quad]
            F += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
    return V, F


def genus_cases():
    V, F = torus()
    write("genus1_torus.obj", obj_text(V, F, "a torus (genus 1), 48 vertices"))
    # A 5 x 3 x 1 slab of cubes with two cells removed: a plate with two holes (genus 2).
    cells = [(x, y, 0) for x in range(5) for y in range(3) if (x, y) not in ((1, 1), (3, 1))]
    V, F = voxel_surface(cells)
    write("genus2.obj", obj_text(V, F, "a plate with two holes (genus 2), the surface of 13 unit cubes"))


def garbage_case():
    # Bytes from a fixed linear congruential sequence: not text, not a mesh.
    x, out = 12345, bytearray()
    for _ in range(2048):
        x = (1103515245 * x + 12345) % 2**31
        out.append((x >> 16) & 0xFF)
    write("obj_binary_garbage.obj", bytes(out))


if __name__ == "__main__":
    ply_cases()
    stl_cases()
    gltf_cases()
    genus_cases()
    garbage_case()
