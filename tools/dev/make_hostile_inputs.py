"""Write the hostile-input corpus into a folder: scenes that try to read outside their
folder, block, exhaust memory or time, or describe impossible cameras and materials.

Run: python3 tools/dev/make_hostile_inputs.py OUT
     python3 tools/dev/make_hostile_inputs.py --exr-claiming PART.exr SIZE OUT.exr

OUT/secret.txt and OUT/secret.usda lie outside the scenes' folder OUT/scenes/, which holds
every scene; some cases need special files (a FIFO, a symbolic link, a sparse 3 GB file),
which is why the corpus is made at test time rather than committed. tests/hostile.rs says
what gridtrace must do with each case. Everything here is written from scratch except the
corrupt binary USD layer, which is the fuzzer's crasher in tests/data/fuzz_crashes/usd/.
"""

import gzip
import json
import math
import os
import random
import struct
import sys
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_bad_inputs import QUAD, QUAD_INDICES, buffer_bytes, document  # noqa: E402

# Words a leak would show: as text, and as the little-endian integers an index accessor
# would make of them (tests/hostile.rs checks neither appears in any message).
SECRET = b"TOPSECRET-canary-7f3a-gridtrace-hostile-input-corpus!!!!"


def quad_bytes():
    return buffer_bytes(QUAD, QUAD_INDICES)


def gltf(buffer_uri="quad.bin", byte_length=60, **overrides):
    """tools/dev/make_bad_inputs.py's emissive quad, its buffer in the file `buffer_uri`."""
    doc = document(**overrides)
    doc["buffers"] = [{"uri": buffer_uri, "byteLength": byte_length}]
    return doc


def leaking_gltf(uri):
    """The quad, plus a second buffer at `uri` read as u32 indices: an unconfined reader
    would report its words as out-of-range vertex indices."""
    doc = gltf()
    doc["buffers"].append({"uri": uri, "byteLength": len(SECRET)})
    doc["bufferViews"].append({"buffer": 1, "byteOffset": 0, "byteLength": len(SECRET)})
    doc["accessors"].append({"bufferView": 2, "componentType": 5125, "count": len(SECRET) // 4, "type": "SCALAR"})
    doc["meshes"][0]["primitives"][0]["indices"] = 2
    return doc


def with_camera(camera, node=None):
    doc = gltf()
    doc["cameras"] = [camera]
    doc["nodes"].append(dict(node or {"translation": [0, 0, 3]}, camera=0))
    doc["scenes"][0]["nodes"] = [0, 1]
    return doc


def glass(ior):
    doc = gltf(extensionsUsed=["KHR_materials_transmission", "KHR_materials_ior"])
    doc["materials"].append({"name": "glass", "extensions": {
        "KHR_materials_transmission": {"transmissionFactor": 1.0},
        "KHR_materials_ior": {"ior": ior}}})
    doc["meshes"][0]["primitives"][0]["material"] = 1
    doc["materials"][0]["name"] = "glow"
    return doc


USDA_QUAD = """def Mesh "Quad"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
    rel material:binding = </Glow>
}
def Material "Glow"
{
    token outputs:surface.connect = </Glow/Surface.outputs:surface>
    def Shader "Surface"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:emissiveColor = (1, 1, 1)
        token outputs:surface
    }
}
"""


def textured_material(name, file):
    """A UsdPreviewSurface material `name` whose diffuse colour reads the image `file`."""
    return f"""def Material "{name}"
{{
    token outputs:surface.connect = </{name}/Surface.outputs:surface>
    def Shader "Surface"
    {{
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </{name}/Image.outputs:rgb>
        token outputs:surface
    }}
    def Shader "Image"
    {{
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @{file}@
        float3 outputs:rgb
    }}
}}
"""


def usda(body="", metadata=""):
    return f"#usda 1.0\n(\n    upAxis = \"Y\"\n{metadata})\n\n{USDA_QUAD}{body}"


def star(n, inner=0.9):
    """A concave polygon: `n` corners alternating between radius 1 and `inner`."""
    corners = []
    for i in range(n):
        angle = 2 * math.pi * i / n
        r = 1.0 if i % 2 == 0 else inner
        corners.append((r * math.cos(angle), r * math.sin(angle), 0.0))
    return corners


def write_deflate_bomb(path, root_layer, size):
    """A .usdz whose texture member `big.png` inflates to `size` bytes of zeros."""
    with zipfile.ZipFile(path, "w") as z:
        z.writestr(zipfile.ZipInfo("root.usda"), root_layer)
        info = zipfile.ZipInfo("big.png")
        info.compress_type = zipfile.ZIP_DEFLATED
        chunk = bytes(1 << 24)
        with z.open(info, "w", force_zip64=True) as member:
            for _ in range(size // len(chunk)):
                member.write(chunk)


def write(path, content):
    with open(path, "wb" if isinstance(content, bytes) else "w") as f:
        f.write(content)


def write_json(path, doc):
    write(path, json.dumps(doc))


def make_corpus(out):
    scenes = os.path.join(out, "scenes")
    os.makedirs(scenes, exist_ok=True)
    j = lambda name: os.path.join(scenes, name)
    secret = os.path.join(out, "secret.txt")
    write(secret, SECRET)
    write(os.path.join(out, "secret.usda"), usda())
    write(j("quad.bin"), quad_bytes())

    # 1. Reading outside the roots, and files that are not regular.
    write_json(j("leak_relative.gltf"), leaking_gltf("../secret.txt"))
    write_json(j("leak_absolute.gltf"), leaking_gltf(secret))
    write_json(j("leak_file_uri.gltf"), leaking_gltf("file://" + secret))
    write_json(j("leak_percent.gltf"), leaking_gltf("..%2Fsecret.txt"))
    write_json(j("leak_proc.gltf"), leaking_gltf("/proc/self/environ"))
    os.symlink("../secret.txt", j("link.bin"))
    write_json(j("leak_symlink.gltf"), leaking_gltf("link.bin"))
    os.mkfifo(j("pipe.bin"))
    write_json(j("fifo_buffer.gltf"), gltf("pipe.bin"))
    write_json(j("dev_stdin.gltf"), gltf("/dev/stdin"))
    write_json(j("dev_zero.gltf"), gltf("/dev/zero"))
    # A sparse 3 GB file whose first 60 bytes are the quad: only byteLength is read.
    with open(j("huge.bin"), "wb") as f:
        f.write(quad_bytes())
        f.truncate(3 * 10**9)
    write_json(j("huge_buffer.gltf"), gltf("huge.bin"))
    doc = gltf()
    doc["images"] = [{"uri": "../secret.txt"}]
    doc["textures"] = [{"source": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    write_json(j("image_outside.gltf"), doc)

    # USD layers and textures outside, a FIFO layer.
    write(j("usd_sublayer_outside.usda"), usda(metadata="    subLayers = [@../secret.usda@]\n"))
    write(j("usd_reference_outside.usda"),
          usda(f"def Xform \"Ref\" (\n    prepend references = @{out}/secret.usda@\n)\n{{\n}}\n"))
    os.mkfifo(j("pipe.usda"))
    write(j("usd_reference_fifo.usda"), usda("def Xform \"Ref\" (\n    prepend references = @pipe.usda@\n)\n{\n}\n"))
    write(j("usd_texture_outside.usda"), usda("""def Material "Tex"
{
    token outputs:surface.connect = </Tex/Surface.outputs:surface>
    def Shader "Surface"
    {
        uniform token info:id = "UsdPreviewSurface"
        color3f inputs:diffuseColor.connect = </Tex/Image.outputs:rgb>
        token outputs:surface
    }
    def Shader "Image"
    {
        uniform token info:id = "UsdUVTexture"
        asset inputs:file = @../secret.txt@
        float3 outputs:rgb
    }
}
def Mesh "Floor"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1)]
    rel material:binding = </Tex>
}
"""))

    # 2. Aborts: a corrupt binary layer behind a text one; nesting past any stack.
    with open(os.path.join(ROOT, "tests", "data", "fuzz_crashes", "usd", "oom-usdc-open.usdc"), "rb") as f:
        write(j("corrupt.usdc"), f.read())
    write(j("usd_corrupt_reference.usda"), usda("def Xform \"Ref\" (\n    prepend references = @corrupt.usdc@\n)\n{\n}\n"))
    write(j("usd_corrupt_sublayer.usda"), usda(metadata="    subLayers = [@corrupt.usdc@]\n"))
    # Deep, but not past the parser's limit: the prim walk's own limit answers.
    write(j("usd_deep_hierarchy.usda"), usda("".join(f"def Xform \"P{i}\" {{\n" for i in range(300)) + "}\n" * 300))
    depth = 10000
    write(j("usd_deep_prims.usda"), usda("".join(f"def Xform \"P{i}\" {{\n" for i in range(depth)) + "}\n" * depth))
    write(j("usd_deep_dictionary.usda"),
          usda(metadata="    customLayerData = " + "{ dictionary d = " * depth + "{}" + " }" * depth + "\n"))
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nelement face 120000000\nproperty list uchar int vertex_indices\nend_header\n")
    payload = header.encode() + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    # Random bytes do not compress: the gzip file is as large as its payload (1.6 MB), so
    # the declared faces fit its size and only the memory they need refuses them.
    payload += random.Random(7).randbytes(1_600_000)
    write(j("many_faces.ply.gz"), gzip.compress(payload, 1))

    # 3. Time: one polygon of 100k corners in a PLY (a fan across the whole grid), a
    # concave one of 200k in USD.
    n = 100_000
    ply = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n" % n).encode()
    ply += b"".join(struct.pack("<3f", math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0)
                    for i in range(n))
    ply += struct.pack("<i", n) + struct.pack("<%di" % n, *range(n))
    write(j("ply_big_polygon.ply"), ply)
    corners = star(200_000)
    points = ", ".join(f"({x:.6f}, {y:.6f}, {z})" for x, y, z in corners)
    write(j("usd_big_polygon.usda"), usda(f"""def Mesh "Star"
{{
    int[] faceVertexCounts = [{len(corners)}]
    int[] faceVertexIndices = [{", ".join(str(i) for i in range(len(corners)))}]
    point3f[] points = [{points}]
    rel material:binding = </Glow>
}}
"""))

    # 5. Content silently dropped, impossible cameras and materials, overflowing counts.
    write(j("usd_missing_sublayer.usda"), usda(metadata="    subLayers = [@not_there.usda@]\n"))
    write(j("broken.usda"), "#usda 1.0\ndef Xform \"X\" {{{ oops\n")
    write(j("usd_broken_reference.usda"), usda("def Xform \"Ref\" (\n    prepend references = @broken.usda@\n)\n{\n}\n"))
    write(j("usd_negative_counts.usda"), usda("""def Mesh "Bad"
{
    int[] faceVertexCounts = [-3, 7]
    int[] faceVertexIndices = [0, 1, 2, 3]
    point3f[] points = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
}
"""))
    # Composition loops and packages with odd members.
    write(j("usd_sublayer_cycle.usda"), usda(metadata="    subLayers = [@cycle_b.usda@]\n"))
    write(j("cycle_b.usda"), usda(metadata="    subLayers = [@usd_sublayer_cycle.usda@]\n"))
    write(j("usd_self_reference.usda"),
          usda("def Xform \"Ref\" (\n    prepend references = @usd_self_reference.usda@</Ref>\n)\n{\n}\n"))
    write(j("usd_missing_reference.usda"),
          usda("def Xform \"Ref\" (\n    prepend references = @not_there.usda@\n)\n{\n}\n"))
    write(j("usd_internal_cycle.usda"), usda("""def Xform "A" (
    prepend references = </B>
)
{
}
def Xform "B" (
    prepend references = </A>
)
{
}
"""))
    write(j("usd_huge_counts.usda"), usda("""def Mesh "Huge"
{
    int[] faceVertexCounts = [2147483647, 2147483647]
    int[] faceVertexIndices = [0, 1, 2]
    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
}
"""))
    positions = ", ".join(f"({i % 100}, 0, {i // 100})" for i in range(10_000))
    indices = ", ".join("0" for _ in range(10_000))
    write(j("usd_instancer_bomb.usda"), usda(f"""def PointInstancer "Outer"
{{
    rel prototypes = </Outer/Inner>
    int[] protoIndices = [{indices}]
    point3f[] positions = [{positions}]

    def PointInstancer "Inner"
    {{
        rel prototypes = </Quad>
        int[] protoIndices = [{indices}]
        point3f[] positions = [{positions}]
    }}
}}
"""))
    write(j("usd_instancer_bad_index.usda"), usda("""def PointInstancer "Scatter"
{
    rel prototypes = </Quad>
    int[] protoIndices = [0, 7]
    point3f[] positions = [(0, 0, 0), (3, 0, 0)]
}
"""))
    root = usda(textured_material("Odd", "../escape.png")).replace("</Glow>", "</Odd>", 1)
    with zipfile.ZipFile(j("usdz_odd_members.usdz"), "w", zipfile.ZIP_STORED) as z:
        z.writestr("root.usda", root)
        z.writestr("../escape.png", b"not an image")
        z.writestr("/absolute.png", b"not an image")
    write(j("usd_skel_bad_index.usda"), usda("""def SkelRoot "Rig"
{
    def Skeleton "Skeleton" (
        prepend apiSchemas = ["SkelBindingAPI"]
    )
    {
        uniform token[] joints = ["Root"]
        uniform matrix4d[] bindTransforms = [((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))]
        uniform matrix4d[] restTransforms = [((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1))]
    }
    def Mesh "Skin" (
        prepend apiSchemas = ["SkelBindingAPI"]
    )
    {
        int[] faceVertexCounts = [3]
        int[] faceVertexIndices = [0, 1, 2]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
        int[] primvars:skel:jointIndices = [0, 7, 0] (
            elementSize = 1
            interpolation = "vertex"
        )
        float[] primvars:skel:jointWeights = [1, 1, 1] (
            elementSize = 1
            interpolation = "vertex"
        )
        rel skel:skeleton = </Rig/Skeleton>
    }
}
"""))
    bomb = usda(textured_material("Bomb", "big.png")).replace("</Glow>", "</Bomb>", 1)
    # 2.5 GiB of zeros deflated to a few megabytes: past the 2 GiB the test allows.
    write_deflate_bomb(j("usdz_deflate_bomb.usdz"), bomb, 5 << 29)

    write_json(j("camera_yfov_zero.gltf"), with_camera({"type": "perspective", "perspective": {"yfov": 0.0, "znear": 0.1}}))
    write_json(j("camera_yfov_infinite.gltf"), with_camera({"type": "perspective", "perspective": {"yfov": 1e39, "znear": 0.1}}))
    write_json(j("camera_ortho_zero.gltf"), with_camera(
        {"type": "orthographic", "orthographic": {"xmag": 0.0, "ymag": 0.0, "znear": 0.1, "zfar": 10}}))
    write_json(j("camera_zero_matrix.gltf"), with_camera(
        {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}, {"matrix": [0.0] * 16}))
    doc = gltf()
    doc["nodes"] = [{"mesh": 0, "scale": [0, 0, 0]}]
    write_json(j("zero_scale.gltf"), doc)
    write_json(j("ior_negative.gltf"), glass(-1.5))
    write_json(j("ior_infinite.gltf"), glass(1e39))
    doc = gltf()
    doc["accessors"][0]["count"] = 2**62 + 1
    write_json(j("count_overflow.gltf"), doc)


def exr_claiming(part, size, out):
    """`part` (a gridtrace EXR) with a header that claims `size`×`size` pixels in ZIP
    blocks and no pixel data: a few kilobytes that ask for gigabytes."""
    with open(part, "rb") as f:
        data = f.read()
    pos, attributes = 8, []
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (length,) = struct.unpack_from("<i", data, type_end + 1)
        value = data[type_end + 5:type_end + 5 + length]
        attributes.append((data[pos:name_end], data[name_end + 1:type_end], value))
        pos = type_end + 5 + length
    header = bytearray(data[:8])
    for name, kind, value in attributes:
        if name in (b"dataWindow", b"displayWindow"):
            value = struct.pack("<4i", 0, 0, size - 1, size - 1)
        elif name == b"compression":
            value = b"\x03"  # ZIP, 16 scanlines a block
        elif name == b"gridtrace/record":
            lines = [l for l in value.decode().split("\n")]
            lines = [f"width={size}" if l.startswith("width=") else
                     f"height={size}" if l.startswith("height=") else l for l in lines]
            value = "\n".join(lines).encode()
        header += name + b"\0" + kind + b"\0" + struct.pack("<i", len(value)) + value
    header += b"\0"
    header += bytes(8 * ((size + 15) // 16))  # the offset table, pointing nowhere
    write(out, bytes(header))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--exr-claiming":
        exr_claiming(sys.argv[2], int(sys.argv[3]), sys.argv[4])
    elif len(sys.argv) == 2:
        make_corpus(os.path.abspath(sys.argv[1]))
    else:
        sys.exit(__doc__)
