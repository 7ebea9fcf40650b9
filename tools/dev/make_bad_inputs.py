"""Write the corpus of broken and hostile scene files in tests/data/bad/.

Run from the repository root: python3 tools/dev/make_bad_inputs.py
Each file is small and made here from scratch (the truncated .glb is cut from the bundled
Cornell box). tests/bad_inputs.rs says what gridtrace must do with each one.
"""

import base64
import json
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "tests", "data", "bad")

QUAD = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
QUAD_INDICES = [0, 1, 2, 0, 2, 3]


def buffer_bytes(positions, indices):
    data = b"".join(struct.pack("<3f", *p) for p in positions)
    data += b"".join(struct.pack("<H", i) for i in indices)
    while len(data) % 4:
        data += b"\0"
    return data


def document(positions=QUAD, indices=QUAD_INDICES, emissive=True, **overrides):
    """A one-quad glTF with an embedded buffer; `overrides` replace top-level keys."""
    data = buffer_bytes(positions, indices)
    npos = len(positions)
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode(), "byteLength": len(data)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 12 * npos},
            {"buffer": 0, "byteOffset": 12 * npos, "byteLength": 2 * len(indices)},
        ],
        "accessors": [
            # min/max are required for POSITION; they stay finite even when a position is not.
            {"bufferView": 0, "componentType": 5126, "count": npos, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
        "materials": [{"emissiveFactor": [1, 1, 1] if emissive else [0, 0, 0], "pbrMetallicRoughness": {"metallicFactor": 0}}],
        "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    doc.update(overrides)
    return doc


def write(name, content):
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(os.path.join(OUT, name), mode) as f:
        f.write(content)


def write_gltf(name, doc):
    write(name, json.dumps(doc, indent=1))


def main():
    os.makedirs(OUT, exist_ok=True)

    # GLB containers.
    with open(os.path.join(ROOT, "assets", "cornell_box.glb"), "rb") as f:
        glb = f.read()
    write("truncated.glb", glb[: len(glb) // 2])
    write("bad_magic.glb", b"glTX" + glb[4:])
    write("bad_version.glb", glb[:4] + struct.pack("<I", 3) + glb[8:])

    # JSON and schema problems.
    write("syntax_error.gltf", json.dumps(document())[:-20] + ",,}")
    doc = document()
    doc["accessors"][0]["count"] = 40
    write_gltf("accessor_past_view.gltf", doc)
    doc = document()
    doc["accessors"][0]["count"] = 10**9
    write_gltf("absurd_count.gltf", doc)
    write_gltf("index_out_of_range.gltf", document(indices=[0, 1, 2, 0, 2, 9]))
    doc = document()
    doc["bufferViews"][0]["byteStride"] = 4
    write_gltf("overlapping_stride.gltf", doc)
    doc = document()
    doc["buffers"][0] = {"uri": "missing.bin", "byteLength": 60}
    write_gltf("missing_buffer.gltf", doc)
    doc = document()
    doc["images"] = [{"uri": "missing%20texture.png"}]
    doc["textures"] = [{"source": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    write_gltf("missing_image.gltf", doc)
    write_gltf("unknown_required_extension.gltf", document(extensionsUsed=["EXT_teleport"], extensionsRequired=["EXT_teleport"]))
    write_gltf("cyclic_nodes.gltf", document(nodes=[{"mesh": 0, "children": [1]}, {"children": [0]}]))
    deep = [{"children": [i + 1]} for i in range(999)] + [{"mesh": 0}]
    write_gltf("deep_nodes.gltf", document(nodes=deep))
    # An animation channel whose target is a node the file does not have.
    animation = {"samplers": [{"input": 1, "output": 0}], "channels": [{"sampler": 0, "target": {"node": 99, "path": "translation"}}]}
    write_gltf("animation_target_missing.gltf", document(animations=[animation]))

    # Geometry that cannot be hit, or nothing to render.
    nan = float("nan")
    write_gltf("nan_positions.gltf", document(positions=[(-1, -1, 0), (1, -1, 0), (1, 1, 0), (nan, 1, 0)]))
    write_gltf("inf_positions.gltf", document(positions=[(-1, -1, 0), (1, -1, 0), (1, 1, 0), (float("inf"), 1, 0)]))
    write_gltf("degenerate_triangles.gltf", document(indices=[0, 1, 2, 0, 0, 3, 1, 1, 1]))
    doc = document()
    doc["meshes"][0]["primitives"][0]["mode"] = 0
    write_gltf("no_triangles.gltf", doc)
    write_gltf("no_emitters.gltf", document(emissive=False))

    # PLY.
    header = "ply\nformat ascii 1.0\nelement vertex {v}\nproperty float x\nproperty float y\nproperty float z\nelement face {f}\nproperty list uchar int vertex_indices\nend_header\n"
    verts = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
    write("truncated.ply", header.format(v=4, f=2) + verts + "3 0 1 2\n")
    write("absurd_count.ply", header.format(v=10**9, f=10**9) + verts)
    write("index_out_of_range.ply", header.format(v=4, f=1) + verts + "3 0 1 7\n")
    binary4 = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    corners = [(0, 0, 0), (1, 0, 0), (float("nan"), 1, 0), (0, 1, 0)]
    faces = [(0, 1, 2), (0, 2, 3)]
    write("nan_vertex.ply", binary4.encode() + b"".join(struct.pack("<3f", *c) for c in corners) + b"".join(struct.pack("<B3i", 3, *f) for f in faces))
    write("not_a_ply.ply", "solid cube\nfacet normal 0 0 1\n")
    binary = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    write("truncated_binary.ply", binary.encode() + struct.pack("<3f", 0, 0, 0) + b"\x01\x02")
    print(f"wrote {len(os.listdir(OUT))} files to {OUT}")


if __name__ == "__main__":
    main()
