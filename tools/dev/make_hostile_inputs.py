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
import warnings
import zipfile
import zlib

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
    # The same layer named by a variable expression, which only composition resolves.
    write(j("usd_expression_reference.usda"), usda(
        "def Xform \"Ref\" (\n    prepend references = @`\"./${V}.usdc\"`@\n)\n{\n}\n",
        metadata="    expressionVariables = {\n        string V = \"corrupt\"\n    }\n"))
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
    many = ", ".join(f"@missing_{i}.usda@" for i in range(100_000))
    write(j("usd_many_missing_sublayers.usda"), usda(metadata=f"    subLayers = [{many}]\n"))
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

    make_memory_text_and_silent_cases(j)


def grey_png(width, height, channels=1):
    """A PNG of zeros, `width`×`height`, grey (`channels` 1) or RGBA (4): a few hundred
    kilobytes that decode to `width`·`height`·`channels` bytes (and to 32 bytes a pixel on
    the way to a texture)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    compress = zlib.compressobj(9)
    row = bytes(width * channels + 1)  # filter byte 0, then the row
    idat = b"".join(compress.compress(row) for _ in range(height)) + compress.flush()
    colour_type = {1: 0, 4: 6}[channels]
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def rle_hdr(width, height):
    """A Radiance .hdr of `width`×`height` black pixels in new-style run-length scanlines
    (Ward, Graphics Gems II): a few megabytes that decode to 12 bytes a pixel."""
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    runs = bytearray()
    for _ in range(4):  # R, G, B, E, each a channel of runs of 127 zeros
        left = width
        while left:
            n = min(127, left)
            runs += bytes([128 + n, 0])
            left -= n
    line = bytes([2, 2, width >> 8, width & 255]) + bytes(runs)
    return header + line * height


def grey_jpeg(width, height):
    """A baseline JPEG (ITU T.81) of one mid-grey channel, `width`×`height` (multiples of 8):
    Huffman tables of one 1-bit code each make every 8×8 block two zero bits (DC difference
    0, end of block), so 20000² pixels take 1.6 MB."""
    def segment(marker, body):
        return b"\xff" + bytes([marker]) + struct.pack(">H", len(body) + 2) + body
    one_code = lambda table, symbol: bytes([table]) + bytes([1] + [0] * 15) + bytes([symbol])
    blocks = (width // 8) * (height // 8)
    return (b"\xff\xd8"
            + segment(0xDB, b"\x00" + bytes([1] * 64))  # quantisation table 0
            + segment(0xC0, struct.pack(">BHHB", 8, height, width, 1) + b"\x01\x11\x00")
            + segment(0xC4, one_code(0x00, 0) + one_code(0x10, 0))  # DC: 0; AC: end of block
            + segment(0xDA, b"\x01\x01\x00\x00\x3f\x00")
            + bytes((2 * blocks + 7) // 8) + b"\xff\xd9")


def black_zip_exr(width, height):
    """An OpenEXR of black half-float RGB in ZIP blocks of 16 scanlines (OpenEXR file
    layout: header, offset table, chunks): a few hundred kilobytes that decode to
    `width`·`height`·6 bytes, and 40 bytes a pixel as an environment map."""
    def attribute(name, kind, value):
        return name + b"\0" + kind + b"\0" + struct.pack("<i", len(value)) + value
    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in (b"B", b"G", b"R")) + b"\0"
    window = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2)
              + attribute(b"channels", b"chlist", channels)
              + attribute(b"compression", b"compression", b"\x03")
              + attribute(b"dataWindow", b"box2i", window)
              + attribute(b"displayWindow", b"box2i", window)
              + attribute(b"lineOrder", b"lineOrder", b"\x00")
              + attribute(b"pixelAspectRatio", b"float", struct.pack("<f", 1))
              + attribute(b"screenWindowCenter", b"v2f", struct.pack("<2f", 0, 0))
              + attribute(b"screenWindowWidth", b"float", struct.pack("<f", 1))
              + b"\0")
    lines = 16
    count = (height + lines - 1) // lines
    # Zeros after the ZIP predictor: the first byte, then differences of 0 stored as 128.
    def block(n):
        size = n * width * 3 * 2
        return zlib.compress(b"\0" + b"\x80" * (size - 1), 9)
    full, chunks, offset = block(lines), [], len(header) + 8 * count
    offsets = []
    for k in range(count):
        n = min(lines, height - k * lines)
        data = full if n == lines else block(n)
        chunk = struct.pack("<ii", k * lines, len(data)) + data
        offsets.append(offset)
        offset += len(chunk)
        chunks.append(chunk)
    return header + struct.pack(f"<{count}Q", *offsets) + b"".join(chunks)


def flat_hdr(width, height):
    """A Radiance .hdr of grey pixels stored flat (4 bytes each, no run-length coding)."""
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    return header + bytes([128, 128, 128, 129]) * (width * height)


def grid_mesh(name, n, spacing=1.0, extra=""):
    """A Mesh prim of n×n quads in the XY plane."""
    points = ", ".join(f"({x * spacing:g}, {y * spacing:g}, 0)" for y in range(n + 1) for x in range(n + 1))
    corners = []
    for y in range(n):
        for x in range(n):
            a = y * (n + 1) + x
            corners += [a, a + 1, a + n + 2, a + n + 1]
    return f"""def Mesh "{name}"
{{
{extra}    int[] faceVertexCounts = [{", ".join(["4"] * (n * n))}]
    int[] faceVertexIndices = [{", ".join(map(str, corners))}]
    point3f[] points = [{points}]
}}
"""


def webp_header(width, height):
    """The first bytes of a lossless WebP of `width`×`height` (RIFF, a VP8L chunk, its
    14-bit sizes; WebP Lossless Bitstream §3): what a decoder sizes its output from."""
    bits = (width - 1) | ((height - 1) << 14) | (1 << 28)  # alpha used, version 0
    payload = b"\x2f" + struct.pack("<I", bits) + bytes(8)
    chunk = b"VP8L" + struct.pack("<I", len(payload)) + payload
    return b"RIFF" + struct.pack("<I", 4 + len(chunk)) + b"WEBP" + chunk


def textured_gltf(uri):
    """The quad with a base colour texture read from `uri`."""
    doc = gltf()
    doc["images"] = [{"uri": uri}]
    doc["textures"] = [{"source": 0}]
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    return doc


def make_memory_text_and_silent_cases(j):
    """Memory for the whole process, decompression bombs, text that would reach a
    terminal, and results that would be silently wrong."""
    # Buffers that meshopt decodes into are zeros of their byteLength: two of 2.5 GB.
    doc = gltf()
    fallback = {"byteLength": 5 << 29, "extensions": {"EXT_meshopt_compression": {"fallback": True}}}
    doc["buffers"] += [dict(fallback), dict(fallback)]
    doc["extensionsUsed"] = ["EXT_meshopt_compression"]
    write_json(j("meshopt_huge_fallback.gltf"), doc)
    # An accessor without a buffer view is zeros of its count.
    doc = gltf()
    del doc["accessors"][0]["bufferView"]
    doc["accessors"][0]["count"] = 300_000_000
    write_json(j("zero_filled_positions.gltf"), doc)
    doc = gltf()
    del doc["accessors"][1]["bufferView"]
    doc["accessors"][1]["count"] = 300_000_000
    write_json(j("zero_filled_indices.gltf"), doc)
    # A sparse accessor over zeros sets one of its 3·10⁸ positions.
    doc = gltf()
    del doc["accessors"][0]["bufferView"]
    doc["accessors"][0]["count"] = 300_000_000
    doc["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                                     "values": {"bufferView": 0}}
    write_json(j("zero_filled_sparse.gltf"), doc)
    # An animation sampler whose key times are 3·10⁸ zeros (read with --frame).
    doc = gltf()
    doc["accessors"].append({"componentType": 5126, "count": 300_000_000, "type": "SCALAR", "min": [0], "max": [0]})
    doc["animations"] = [{"samplers": [{"input": 2, "output": 0}],
                          "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}]
    write_json(j("zero_filled_animation.gltf"), doc)
    # Image bombs: a 12000² grey PNG (about 150 kB) as a texture, in a .gltf and a .usdz.
    write(j("bomb.png"), grey_png(12000, 12000))
    write_json(j("png_bomb.gltf"), textured_gltf("bomb.png"))
    with zipfile.ZipFile(j("usdz_png_bomb.usdz"), "w") as z:
        z.writestr("root.usda", usda(textured_material("Bomb", "bomb.png")).replace("</Glow>", "</Bomb>", 1))
        z.write(j("bomb.png"), "bomb.png")
    write(j("bomb.webp"), webp_header(16383, 16383))
    write_json(j("webp_bomb.gltf"), textured_gltf("bomb.webp"))
    write(j("bomb.jpg"), grey_jpeg(20000, 20000))
    write_json(j("jpeg_bomb.gltf"), textured_gltf("bomb.jpg"))
    write(j("bomb_rgba.png"), grey_png(16000, 16000, channels=4))
    write_json(j("rgba_png_bomb.gltf"), textured_gltf("bomb_rgba.png"))
    # One image spelt four ways decodes once (tests/hostile.rs counts the textures).
    os.makedirs(j("sub"), exist_ok=True)
    write(j("t.png"), grey_png(4, 4))
    doc = textured_gltf("t.png")
    doc["images"] = [{"uri": u} for u in ["t.png", "./t.png", "sub/../t.png", "%74.png"]]
    doc["textures"] = [{"source": i} for i in range(4)]
    doc["materials"] = [dict(doc["materials"][0], pbrMetallicRoughness={"baseColorTexture": {"index": i}}) for i in range(4)]
    doc["meshes"] = [{"primitives": [dict(doc["meshes"][0]["primitives"][0], material=i)]} for i in range(4)]
    doc["nodes"] = [{"mesh": i} for i in range(4)]
    doc["scenes"] = [{"nodes": [0, 1, 2, 3]}]
    write_json(j("texture_aliases.gltf"), doc)
    # An environment map of 12000×6000 in 4.6 MB, and one cut short after 600 bytes.
    write(j("big_rle.hdr"), rle_hdr(12000, 6000))
    write(j("cut.hdr"), flat_hdr(64, 32)[:600])
    dome = """def DomeLight "Sky"
{
    asset inputs:texture:file = @big_rle.hdr@
}
"""
    write(j("usd_dome_bomb.usda"), usda(dome))
    write(j("big_zip.exr"), black_zip_exr(16000, 8000))
    write(j("usd_dome_exr_bomb.usda"), usda(dome.replace("big_rle.hdr", "big_zip.exr")))
    # Subdivision and motion steps under --max-memory: a 1,024-quad cage, and a 25,600-quad
    # mesh that moves (tests/hostile.rs gives the levels, steps and budget).
    write(j("usd_subdivision_cage.usda"), usda(grid_mesh(
        "Cage", 32, extra='    uniform token subdivisionScheme = "catmullClark"\n')))
    moving = grid_mesh("Grid", 160, spacing=0.01)
    write(j("usd_moving_grid.usda"), usda(f"""def Xform "Mover"
{{
    double3 xformOp:translate.timeSamples = {{1: (0, 0, 0), 10: (1, 0, 0)}}
    uniform token[] xformOpOrder = ["xformOp:translate"]
{moving}}}
""", metadata="    startTimeCode = 1\n    endTimeCode = 10\n"))
    # Control characters in names and URIs from the file.
    doc = gltf()
    doc["meshes"][0]["name"] = "quad\x1b[2J\nerror: forged second line"
    doc["accessors"][1]["count"] = 7  # reads past its view: an error naming the mesh
    write_json(j("escape_in_name.gltf"), doc)
    write_json(j("escape_in_uri.gltf"), textured_gltf("\x1b]0;owned\x07missing.png"))
    # A hard link inside the folder to a file outside it: read (it is the file itself), but
    # no message may show its bytes.
    os.link(os.path.join(os.path.dirname(j("x")), "..", "secret.txt"), j("hardlink.bin"))
    write_json(j("leak_hardlink.gltf"), leaking_gltf("hardlink.bin"))
    # Geometry scaled past what 32-bit floats can trace.
    doc = gltf()
    doc["nodes"] = [{"mesh": 0, "scale": [1e38, 1e38, 1e38]}]
    write_json(j("huge_scale.gltf"), doc)
    # Clipping that would hide everything.
    write_json(j("camera_near_beyond_far.gltf"), with_camera(
        {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 10, "zfar": 1}}))
    write(j("usd_reversed_clipping.usda"), usda("""def Camera "Cam"
{
    float2 clippingRange = (100, 0.1)
    double3 xformOp:translate = (0, 0, 3)
    uniform token[] xformOpOrder = ["xformOp:translate"]
}
"""))
    # Packages: two members of one name, a member in a method usdz does not allow.
    with zipfile.ZipFile(j("usdz_twin_members.usdz"), "w") as z, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "Duplicate name": the point of the case
        z.writestr("scene.usda", usda())
        z.writestr("scene.usda", usda(metadata="    subLayers = [@../secret.usda@]\n"))
    with zipfile.ZipFile(j("usdz_bzip2_member.usdz"), "w") as z:
        z.writestr(zipfile.ZipInfo("scene.usda"), usda(), compress_type=zipfile.ZIP_BZIP2)


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
