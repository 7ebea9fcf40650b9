"""Writes small models the way other tools write the files users download: no lights, no
camera. Run with a Python that has `trimesh`, `pygltflib`, `usd-core` and `materialx` (PyPI):

    python3 -m venv /tmp/tp && /tmp/tp/bin/pip install trimesh pygltflib usd-core numpy materialx
    /tmp/tp/bin/python tools/dev/make_third_party.py tests/data/scenes/third_party

- `trimesh_shapes.glb`: trimesh's glTF exporter, an icosphere on a box with colours.
- `pygltflib_plate.gltf`: a flat square lying in the ground plane (Y up), written
  accessor by accessor with pygltflib, as a flat object such as a watch would be.
- `pygltflib_variants.gltf`: two squares side by side with `KHR_materials_variants`: both
  red by default; variant "Blue" makes both blue, variant "Green" makes only the left
  one green (the right one has no mapping for it and keeps red).
- `usd_core_disc.usda`: Pixar's USD library, a thin Z-up cylinder (a coin) with a
  UsdPreviewSurface bound.
- `usd_core_primvar_colour.usda`: a plate whose diffuseColor reads displayColor through a
  UsdPrimvarReader_float3 (red corners on the left, blue on the right).
- `usd_core_materialx.usda` with `materialx/looks.mtlx` (MaterialX's own Python library,
  PyPI `materialx`): four balls whose materials reference MaterialX documents, as studios
  keep their looks: an OpenPBR gold with a coat, a Standard Surface amber glass, a
  Standard Surface brass whose colour is a tiled checker image (written here as a PNG),
  and an OpenPBR surface whose colour comes from a `noise2d` node (not read: one warning).
"""

import base64
import struct
import sys
import zlib
from pathlib import Path

import numpy as np


def trimesh_shapes(out: Path) -> None:
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=3, radius=0.5)
    ball.apply_translation([0.0, 1.0, 0.0])
    ball.visual.vertex_colors = [200, 60, 40, 255]
    box = trimesh.creation.box(extents=[1.6, 1.0, 1.0])
    box.visual.vertex_colors = [90, 140, 200, 255]
    trimesh.Scene([ball, box]).export(out / "trimesh_shapes.glb")


def pygltflib_plate(out: Path) -> None:
    import pygltflib as g

    positions = np.array(
        [[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], dtype=np.float32
    )
    indices = np.array([0, 2, 1, 0, 3, 2], dtype=np.uint16)
    blob = positions.tobytes() + indices.tobytes()
    gltf = g.GLTF2(
        scene=0,
        scenes=[g.Scene(nodes=[0])],
        nodes=[g.Node(mesh=0, name="plate")],
        meshes=[
            g.Mesh(
                primitives=[
                    g.Primitive(
                        attributes=g.Attributes(POSITION=0), indices=1, material=0
                    )
                ]
            )
        ],
        materials=[
            g.Material(
                pbrMetallicRoughness=g.PbrMetallicRoughness(
                    baseColorFactor=[0.9, 0.8, 0.3, 1.0],
                    metallicFactor=0.0,
                    roughnessFactor=0.6,
                ),
                doubleSided=True,
            )
        ],
        accessors=[
            g.Accessor(
                bufferView=0,
                componentType=g.FLOAT,
                count=4,
                type=g.VEC3,
                min=[-1.0, 0.0, -1.0],
                max=[1.0, 0.0, 1.0],
            ),
            g.Accessor(
                bufferView=1, componentType=g.UNSIGNED_SHORT, count=6, type=g.SCALAR
            ),
        ],
        bufferViews=[
            g.BufferView(buffer=0, byteOffset=0, byteLength=positions.nbytes),
            g.BufferView(
                buffer=0, byteOffset=positions.nbytes, byteLength=indices.nbytes
            ),
        ],
        buffers=[
            g.Buffer(
                byteLength=len(blob),
                uri="data:application/octet-stream;base64,"
                + base64.b64encode(blob).decode(),
            )
        ],
    )
    gltf.save(str(out / "pygltflib_plate.gltf"))


def pygltflib_variants(out: Path) -> None:
    import pygltflib as g

    # Two unit squares in the ground plane, x in [-2, 0] and [0, 2].
    left = np.array([[-2, 0, -1], [0, 0, -1], [0, 0, 1], [-2, 0, 1]], dtype=np.float32)
    right = left + np.array([2, 0, 0], dtype=np.float32)
    indices = np.array([0, 2, 1, 0, 3, 2], dtype=np.uint16)
    blob = left.tobytes() + right.tobytes() + indices.tobytes()

    def colour(name, rgb):
        return g.Material(
            name=name,
            pbrMetallicRoughness=g.PbrMetallicRoughness(
                baseColorFactor=[*rgb, 1.0], metallicFactor=0.0, roughnessFactor=0.7),
            doubleSided=True,
        )

    def square(position, mappings):
        return g.Primitive(
            attributes=g.Attributes(POSITION=position), indices=2, material=0,
            extensions={"KHR_materials_variants": {"mappings": mappings}},
        )

    def bounds(points):
        return dict(min=points.min(axis=0).tolist(), max=points.max(axis=0).tolist())

    gltf = g.GLTF2(
        scene=0,
        scenes=[g.Scene(nodes=[0])],
        nodes=[g.Node(mesh=0, name="squares")],
        meshes=[g.Mesh(primitives=[
            square(0, [{"material": 1, "variants": [0]}, {"material": 2, "variants": [1]}]),
            square(1, [{"material": 1, "variants": [0]}]),
        ])],
        materials=[colour("Red", [0.8, 0.1, 0.1]), colour("Blue", [0.1, 0.1, 0.8]),
                   colour("Green", [0.1, 0.8, 0.1])],
        extensionsUsed=["KHR_materials_variants"],
        extensions={"KHR_materials_variants": {"variants": [{"name": "Blue"}, {"name": "Green"}]}},
        accessors=[
            g.Accessor(bufferView=0, componentType=g.FLOAT, count=4, type=g.VEC3, **bounds(left)),
            g.Accessor(bufferView=1, componentType=g.FLOAT, count=4, type=g.VEC3, **bounds(right)),
            g.Accessor(bufferView=2, componentType=g.UNSIGNED_SHORT, count=6, type=g.SCALAR),
        ],
        bufferViews=[
            g.BufferView(buffer=0, byteOffset=0, byteLength=left.nbytes),
            g.BufferView(buffer=0, byteOffset=left.nbytes, byteLength=right.nbytes),
            g.BufferView(buffer=0, byteOffset=2 * left.nbytes, byteLength=indices.nbytes),
        ],
        buffers=[g.Buffer(byteLength=len(blob), uri="data:application/octet-stream;base64,"
                          + base64.b64encode(blob).decode())],
    )
    gltf.save(str(out / "pygltflib_variants.gltf"))


def usd_core_disc(out: Path) -> None:
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade

    stage = Usd.Stage.CreateNew(str(out / "usd_core_disc.usda"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Coin")
    stage.SetDefaultPrim(root.GetPrim())
    segments, radius, half = 48, 1.0, 0.08
    points, counts, indices = [], [], []
    for z in (-half, half):
        for i in range(segments):
            a = 2 * np.pi * i / segments
            points.append(Gf.Vec3f(radius * np.cos(a), radius * np.sin(a), z))
    for i in range(segments):
        j = (i + 1) % segments
        counts.append(4)
        indices += [i, j, segments + j, segments + i]
    counts += [segments, segments]
    indices += list(reversed(range(segments))) + [segments + i for i in range(segments)]
    mesh = UsdGeom.Mesh.Define(stage, "/Coin/Disc")
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr(counts)
    mesh.CreateFaceVertexIndicesAttr(indices)
    material = UsdShade.Material.Define(stage, "/Coin/Gold")
    shader = UsdShade.Shader.Define(stage, "/Coin/Gold/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set((1.0, 0.78, 0.34))
    shader.CreateInput("metallic", Sdf.ValueTypeNames.Float).Set(1.0)
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.3)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()


def usd_core_primvar_colour(out: Path) -> None:
    """A plate whose UsdPreviewSurface takes its diffuseColor from the mesh's displayColor
    through a UsdPrimvarReader_float3, as the USD working group's assets do: red on the
    left corners, blue on the right."""
    from pxr import Sdf, Usd, UsdGeom, UsdShade

    stage = Usd.Stage.CreateNew(str(out / "usd_core_primvar_colour.usda"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    root = UsdGeom.Xform.Define(stage, "/Plate")
    stage.SetDefaultPrim(root.GetPrim())
    mesh = UsdGeom.Mesh.Define(stage, "/Plate/Mesh")
    mesh.CreatePointsAttr([(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 3, 2, 1])
    colours = mesh.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex)
    colours.Set([(0.8, 0.05, 0.05), (0.05, 0.05, 0.8), (0.05, 0.05, 0.8), (0.8, 0.05, 0.05)])
    material = UsdShade.Material.Define(stage, "/Plate/Painted")
    shader = UsdShade.Shader.Define(stage, "/Plate/Painted/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    reader = UsdShade.Shader.Define(stage, "/Plate/Painted/DisplayColor")
    reader.CreateIdAttr("UsdPrimvarReader_float3")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("displayColor")
    reader.CreateOutput("result", Sdf.ValueTypeNames.Float3)
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
        reader.ConnectableAPI(), "result")
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.8)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    UsdShade.MaterialBindingAPI.Apply(mesh.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()


def write_png(path: Path, rgb: np.ndarray) -> None:
    """An 8-bit RGB PNG (ISO/IEC 15948: signature, IHDR, one IDAT, IEND)."""
    height, width, _ = rgb.shape
    rows = b"".join(b"\x00" + rgb[y].astype(np.uint8).tobytes() for y in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                     + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def materialx_looks(folder: Path) -> None:
    """`looks.mtlx`, written with MaterialX's document API, and its checker texture."""
    import MaterialX as mx

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "textures").mkdir(exist_ok=True)
    check = (np.indices((8, 8)).sum(axis=0) % 2)[..., None]
    write_png(folder / "textures" / "checker.png",
              np.where(check == 1, [230, 180, 60], [60, 40, 20]))
    doc = mx.createDocument()
    doc.setColorSpace("lin_rec709")

    def material(name: str, shader: mx.Node) -> None:
        look = doc.addMaterialNode(name, shader)
        assert look is not None

    gold = doc.addNode("open_pbr_surface", "SR_gold", "surfaceshader")
    gold.setInputValue("base_color", mx.Color3(1.0, 0.766, 0.336))
    gold.setInputValue("base_metalness", 1.0)
    gold.setInputValue("specular_roughness", 0.3)
    gold.setInputValue("coat_weight", 0.4)
    gold.setInputValue("coat_roughness", 0.05)
    material("Gold", gold)

    glass = doc.addNode("standard_surface", "SR_amber", "surfaceshader")
    glass.setInputValue("transmission", 1.0)
    glass.setInputValue("transmission_color", mx.Color3(1.0, 0.6, 0.2))
    glass.setInputValue("specular_roughness", 0.05)
    glass.setInputValue("specular_IOR", 1.52)
    material("Amber", glass)

    graph = doc.addNodeGraph("NG_brass")
    graph.setFilePrefix("textures/")
    image = graph.addNode("tiledimage", "checker", "color3")
    image.setInputValue("file", "checker.png", "filename")
    image.getInput("file").setColorSpace("srgb_texture")
    image.setInputValue("uvtiling", mx.Vector2(4.0, 2.0))
    graph.addOutput("out_color", "color3").setConnectedNode(image)
    brass = doc.addNode("standard_surface", "SR_brass", "surfaceshader")
    brass.setInputValue("base", 1.0)
    brass.setInputValue("metalness", 1.0)
    brass.setInputValue("specular_roughness", 0.35)
    brass_colour = brass.addInput("base_color", "color3")
    brass_colour.setNodeGraphString("NG_brass")
    brass_colour.setOutputString("out_color")
    material("Brass", brass)

    noise = doc.addNode("noise2d", "grain", "color3")
    noise.setInputValue("amplitude", mx.Vector3(1.0, 1.0, 1.0))
    noisy = doc.addNode("open_pbr_surface", "SR_noisy", "surfaceshader")
    noisy.addInput("base_color", "color3").setConnectedNode(noise)
    noisy.setInputValue("specular_roughness", 0.6)
    material("Noisy", noisy)

    valid, why = doc.validate()
    assert valid, why
    mx.writeToXmlFile(doc, str(folder / "looks.mtlx"))


def usd_core_materialx(out: Path) -> None:
    """Four balls in a row, each bound to a Material that references a look of
    `materialx/looks.mtlx` (`@./materialx/looks.mtlx@</MaterialX/Materials/NAME>`)."""
    from pxr import Usd, UsdGeom, UsdShade

    materialx_looks(out / "materialx")
    stage = Usd.Stage.CreateNew(str(out / "usd_core_materialx.usda"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    root = UsdGeom.Xform.Define(stage, "/Balls")
    stage.SetDefaultPrim(root.GetPrim())
    for i, name in enumerate(["Gold", "Amber", "Brass", "Noisy"]):
        material = UsdShade.Material.Define(stage, f"/Balls/Looks/{name}")
        material.GetPrim().GetReferences().AddReference(
            "./materialx/looks.mtlx", f"/MaterialX/Materials/{name}")
        ball = UsdGeom.Sphere.Define(stage, f"/Balls/{name}Ball")
        ball.CreateRadiusAttr(0.45)
        ball.AddTranslateOp().Set((i - 1.5, 0.5, 0.0))
        UsdShade.MaterialBindingAPI.Apply(ball.GetPrim()).Bind(material)
    stage.GetRootLayer().Save()


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    trimesh_shapes(out)
    pygltflib_plate(out)
    pygltflib_variants(out)
    usd_core_disc(out)
    usd_core_primvar_colour(out)
    usd_core_materialx(out)
