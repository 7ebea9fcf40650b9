"""Writes the USD pipeline test stages with Pixar's own library, and beside each the answers
Pixar's library computes for it (`expected.json`), so the loader is checked against USD
itself rather than against our reading of the specification. Run with a Python that has
`usd-core` and `pillow` (PyPI):

    python3 -m venv /tmp/tp && /tmp/tp/bin/pip install usd-core pillow
    /tmp/tp/bin/python tools/dev/make_usd_pipeline.py tests/data/scenes/usd_pipeline

Stages (Y up, metres, so USD's numbers are gridtrace's):
- `assets/`: a root stage with a sublayer and a reference in other folders, each naming a
  texture relative to itself; decoys of a different colour sit where anchoring to the
  root stage would look. Answers: `Sdf.ComputeAssetPathRelativeToLayer` and the resolved
  path of every texture.
- `package.usdz`: the same kind of stage packed by `UsdUtils.CreateNewUsdzPackage`
  (a layer and a texture in nested folders inside the archive).
- `materials.usda`: NodeGraph-wrapped surfaces with interface inputs, inherited,
  `strongerThanDescendants`, purpose and collection bindings, displayColor fallbacks.
  Answers: `ComputeBoundMaterial` (full purpose), `ComputeSurfaceSource` and the value
  producing the diffuse colour.
- `prims.usda`: `over` and `class` prims beside defined ones. Answer: the gprims
  `Usd.PrimRange` visits with the default predicate.
- `instancer.usda`: a PointInstancer with two prototypes, orientations, scales, invisible
  ids and time-sampled positions. Answer: `ComputeInstanceTransformsAtTime` times the
  instancer's `UsdGeomXformCache` transform at frame 4.
- `implicit.usda`: Sphere, Cube, Cylinder, Cone, Capsule and Plane prims. Answer: each
  prim's world bounds from `UsdGeom.BBoxCache`.
- `skinned.usdc` (written by `tools/blender/make_usd_skinning.py`, run it first): its
  skinning baked by `UsdSkel.BakeSkinning`. Answer (`skinned_baked.json`): the mesh's
  world-space points at frames 1, 9 and 17.
"""

import json
import shutil
import sys
import tempfile
from pathlib import Path

from PIL import Image
from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, UsdUtils, Vt

FRAME = 4.0


def png(path: Path, rgb) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (4, 4), rgb).save(path)


def new_stage(path: Path) -> Usd.Stage:
    path.parent.mkdir(parents=True, exist_ok=True)
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    return stage


def quad(stage, path: str, y: float = 0.0, size: float = 1.0) -> UsdGeom.Mesh:
    """A square facing +Y with st coordinates, `size` wide, at height `y`."""
    mesh = UsdGeom.Mesh.Define(stage, path)
    h = 0.5 * size
    mesh.CreatePointsAttr([(-h, y, h), (h, y, h), (h, y, -h), (-h, y, -h)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    st = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar(
        "st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.faceVarying
    )
    st.Set([(0, 0), (1, 0), (1, 1), (0, 1)])
    return mesh


def preview_surface(stage, path: str, colour=None) -> tuple:
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, path + "/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    if colour is not None:
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*colour))
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material, shader


def textured_material(stage, path: str, texture: str) -> UsdShade.Material:
    material, shader = preview_surface(stage, path)
    reader = UsdShade.Shader.Define(stage, path + "/Texture")
    reader.CreateIdAttr("UsdUVTexture")
    reader.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(texture)
    reader.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(
        reader.ConnectableAPI(), "rgb"
    )
    return material


def texture_answers(stage: Usd.Stage, root: Path) -> dict:
    """Every UsdUVTexture's file: the layer-relative path Sdf computes, and what the
    stage resolves it to, both relative to `root`."""
    answers = {}
    for prim in stage.Traverse():
        shader = UsdShade.Shader(prim)
        if not shader or shader.GetIdAttr().Get() != "UsdUVTexture":
            continue
        attr = shader.GetInput("file").GetAttr()
        layer = attr.GetPropertyStack()[0].layer
        authored = attr.Get().path
        anchored = Sdf.ComputeAssetPathRelativeToLayer(layer, authored)
        resolved = attr.Get().resolvedPath
        answers[str(prim.GetPath())] = {
            "authored": authored,
            "anchored": str(Path(anchored).resolve().relative_to(root.resolve())),
            "resolved": str(Path(resolved).resolve().relative_to(root.resolve())),
        }
    return answers


def assets(out: Path) -> None:
    case = out / "assets"
    shutil.rmtree(case, ignore_errors=True)
    png(case / "layers/textures/floor.png", (200, 30, 30))
    png(case / "props/crate/crate.png", (30, 200, 30))
    # Decoys where anchoring to the root stage's folder would look.
    png(case / "textures/floor.png", (30, 30, 200))
    png(case / "crate.png", (30, 30, 200))

    layer = new_stage(case / "layers/set.usda")
    quad(layer, "/World/Floor")
    textured_material(layer, "/World/Looks/Floor", "textures/floor.png")
    UsdShade.MaterialBindingAPI.Apply(layer.GetPrimAtPath("/World/Floor")).Bind(
        UsdShade.Material(layer.GetPrimAtPath("/World/Looks/Floor"))
    )
    layer.Save()

    prop = new_stage(case / "props/crate/crate.usda")
    crate = UsdGeom.Xform.Define(prop, "/Crate")
    prop.SetDefaultPrim(crate.GetPrim())
    quad(prop, "/Crate/Top", y=0.5, size=0.5)
    material = textured_material(prop, "/Crate/Looks/Wood", "./crate.png")
    UsdShade.MaterialBindingAPI.Apply(prop.GetPrimAtPath("/Crate/Top")).Bind(material)
    prop.Save()

    stage = new_stage(case / "shot.usda")
    stage.GetRootLayer().subLayerPaths.append("layers/set.usda")
    placed = UsdGeom.Xform.Define(stage, "/World/Crate")
    placed.GetPrim().GetReferences().AddReference("props/crate/crate.usda")
    placed.AddTranslateOp().Set(Gf.Vec3d(0.2, 0.0, 0.1))
    stage.Save()
    answers = {"textures": texture_answers(stage, case)}
    (case / "expected.json").write_text(json.dumps(answers, indent=1, sort_keys=True))


def package(out: Path) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp)
        png(src / "maps/deep/wood.png", (180, 120, 40))
        layer = new_stage(src / "parts/board.usda")
        board = UsdGeom.Xform.Define(layer, "/Board")
        layer.SetDefaultPrim(board.GetPrim())
        quad(layer, "/Board/Top")
        material = textured_material(layer, "/Board/Looks/Wood", "../maps/deep/wood.png")
        UsdShade.MaterialBindingAPI.Apply(layer.GetPrimAtPath("/Board/Top")).Bind(material)
        layer.Save()
        stage = new_stage(src / "package.usda")
        root = UsdGeom.Xform.Define(stage, "/Root")
        stage.SetDefaultPrim(root.GetPrim())
        root.GetPrim().GetReferences().AddReference("parts/board.usda")
        stage.Save()
        target = out / "package.usdz"
        target.unlink(missing_ok=True)
        assert UsdUtils.CreateNewUsdzPackage(str(src / "package.usda"), str(target))
    stage = Usd.Stage.Open(str(out / "package.usdz"))
    prim = stage.GetPrimAtPath("/Root/Looks/Wood/Texture")
    resolved = UsdShade.Shader(prim).GetInput("file").GetAttr().Get().resolvedPath
    answers = {"texture_resolved_inside": resolved[resolved.index("[") :]}
    (out / "package.json").write_text(json.dumps(answers, indent=1, sort_keys=True))


def materials(out: Path) -> None:
    stage = new_stage(out / "materials.usda")
    looks = "/World/Looks"
    colours = {
        "Red": (0.8, 0.1, 0.1),
        "Green": (0.1, 0.8, 0.1),
        "Blue": (0.1, 0.1, 0.8),
        "Preview": (0.8, 0.8, 0.1),
    }
    made = {}
    for name, colour in colours.items():
        made[name], _ = preview_surface(stage, f"{looks}/{name}", colour)

    # A surface inside a NodeGraph, fed by the material's interface input.
    graph_material = UsdShade.Material.Define(stage, f"{looks}/Graphed")
    tint = graph_material.CreateInput("tint", Sdf.ValueTypeNames.Color3f)
    tint.Set(Gf.Vec3f(0.2, 0.5, 0.7))
    graph = UsdShade.NodeGraph.Define(stage, f"{looks}/Graphed/Graph")
    graph_tint = graph.CreateInput("baseTint", Sdf.ValueTypeNames.Color3f)
    graph_tint.ConnectToSource(tint)
    graph_rough = graph.CreateInput("rough", Sdf.ValueTypeNames.Float)
    graph_rough.Set(0.3)
    shader = UsdShade.Shader.Define(stage, f"{looks}/Graphed/Graph/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(graph_tint)
    shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).ConnectToSource(graph_rough)
    shader_out = shader.CreateOutput("surface", Sdf.ValueTypeNames.Token)
    graph_out = graph.CreateOutput("surface", Sdf.ValueTypeNames.Token)
    graph_out.ConnectToSource(shader_out)
    graph_material.CreateSurfaceOutput().ConnectToSource(graph_out)

    bind = lambda prim, material, **kw: UsdShade.MaterialBindingAPI.Apply(  # noqa: E731
        prim.GetPrim()
    ).Bind(material, **kw)
    inherited = UsdGeom.Xform.Define(stage, "/World/Inherited")
    bind(inherited, made["Red"])
    quad(stage, "/World/Inherited/Child")
    stronger = UsdGeom.Xform.Define(stage, "/World/Stronger")
    bind(stronger, made["Green"], bindingStrength=UsdShade.Tokens.strongerThanDescendants)
    bind(quad(stage, "/World/Stronger/Child", y=0.1), made["Blue"])
    purposes = quad(stage, "/World/Purposes", y=0.2)
    bind(purposes, made["Red"])
    bind(purposes, made["Blue"], materialPurpose=UsdShade.Tokens.full)
    bind(purposes, made["Preview"], materialPurpose=UsdShade.Tokens.preview)
    preview_only = quad(stage, "/World/PreviewOnly", y=0.25)
    bind(preview_only, made["Preview"], materialPurpose=UsdShade.Tokens.preview)
    bind(preview_only, made["Green"])
    quad(stage, "/World/Collected", y=0.3)
    world = stage.GetPrimAtPath("/World")
    collection = Usd.CollectionAPI.Apply(world, "greens")
    collection.CreateIncludesRel().AddTarget("/World/Collected")
    UsdShade.MaterialBindingAPI.Apply(world).Bind(collection, made["Green"], "greens")
    bind(quad(stage, "/World/Graphed", y=0.4), graph_material)

    constant = quad(stage, "/World/DisplayConstant", y=0.5)
    constant.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([(0.9, 0.5, 0.1)])
    per_face = UsdGeom.Mesh.Define(stage, "/World/DisplayPerFace")
    per_face.CreatePointsAttr([(0, 0.6, 0), (1, 0.6, 0), (1, 0.6, -1), (0, 0.6, -1), (2, 0.6, 0)])
    per_face.CreateFaceVertexCountsAttr([3, 3])
    per_face.CreateFaceVertexIndicesAttr([0, 1, 3, 1, 4, 2])
    per_face.CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform).Set(
        [(0.1, 0.2, 0.9), (0.9, 0.2, 0.1)]
    )
    faded = quad(stage, "/World/DisplayOpacity", y=0.7)
    faded.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set([(0.3, 0.3, 0.3)])
    faded.CreateDisplayOpacityPrimvar(UsdGeom.Tokens.constant).Set([0.25])
    stage.Save()

    answers = {"bound": {}, "surface": {}, "display": {}}
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.Mesh):
            continue
        path = str(prim.GetPath())
        material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial(
            UsdShade.Tokens.full
        )
        if material:
            answers["bound"][path] = str(material.GetPath())
        else:
            colours = UsdGeom.Gprim(prim).GetDisplayColorPrimvar().ComputeFlattened()
            opacity = UsdGeom.Gprim(prim).GetDisplayOpacityPrimvar().ComputeFlattened()
            answers["display"][path] = {
                "colours": [list(c) for c in colours],
                "opacity": list(opacity) if opacity else None,
            }
    for prim in stage.Traverse():
        if not prim.IsA(UsdShade.Material):
            continue
        source = UsdShade.Material(prim).ComputeSurfaceSource()[0]
        diffuse = source.GetInput("diffuseColor")
        values = diffuse.GetValueProducingAttributes()
        roughness = source.GetInput("roughness")
        rough_values = roughness.GetValueProducingAttributes() if roughness else []
        answers["surface"][str(prim.GetPath())] = {
            "shader": str(source.GetPath()),
            "diffuse": list(values[0].Get()),
            "roughness": rough_values[0].Get() if rough_values else 0.5,
        }
    (out / "materials.json").write_text(json.dumps(answers, indent=1, sort_keys=True))


def prims(out: Path) -> None:
    stage = new_stage(out / "prims.usda")
    quad(stage, "/World/Real")
    # A flattened stage's prototypes: a defined mesh under an `over`.
    quad(stage, "/World/Prototypes/Tree", y=1.0)
    stage.GetPrimAtPath("/World/Prototypes").SetSpecifier(Sdf.SpecifierOver)
    stage.CreateClassPrim("/_Base")
    quad(stage, "/_Base/Leaf", y=2.0)
    inherits = quad(stage, "/World/Inheriting", y=3.0)
    inherits.GetPrim().GetInherits().AddInherit("/_Base")
    stage.Save()
    drawn = [
        str(p.GetPath())
        for p in Usd.PrimRange(stage.GetPseudoRoot())
        if p.IsA(UsdGeom.Gprim)
    ]
    (out / "prims.json").write_text(json.dumps({"drawn": drawn}, indent=1))


def matrix_rows(m: Gf.Matrix4d) -> list:
    return [[m[r][c] for c in range(4)] for r in range(4)]


def instancer(out: Path) -> None:
    stage = new_stage(out / "instancer.usda")
    stage.SetStartTimeCode(1)
    stage.SetEndTimeCode(10)
    world = UsdGeom.Xform.Define(stage, "/World")
    world.AddRotateYOp().Set(30.0)
    scatter = UsdGeom.PointInstancer.Define(stage, "/World/Scatter")
    scatter.AddTranslateOp().Set(Gf.Vec3d(1.0, 0.5, -2.0))
    scatter.AddScaleOp().Set(Gf.Vec3f(2.0, 2.0, 2.0))
    UsdGeom.Scope.Define(stage, "/World/Scatter/Protos")
    ball = UsdGeom.Sphere.Define(stage, "/World/Scatter/Protos/Ball")
    ball.CreateRadiusAttr(0.25)
    ball.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.25, 0.0))
    rock = UsdGeom.Xform.Define(stage, "/World/Scatter/Protos/Rock")
    rock.AddRotateXOp().Set(90.0)
    slab = quad(stage, "/World/Scatter/Protos/Rock/Slab", size=0.4)
    slab.AddTranslateOp().Set(Gf.Vec3d(0.1, 0.0, 0.0))
    scatter.CreatePrototypesRel().SetTargets(
        ["/World/Scatter/Protos/Ball", "/World/Scatter/Protos/Rock"]
    )
    count = 6
    scatter.CreateProtoIndicesAttr([i % 2 for i in range(count)])
    positions = scatter.CreatePositionsAttr()
    positions.Set([(i * 0.7, 0.0, 0.0) for i in range(count)], 1.0)
    positions.Set([(i * 0.7, 1.0, 0.5 * i) for i in range(count)], 10.0)
    scatter.CreateOrientationsAttr(
        Vt.QuathArray(
            [Gf.Quath(Gf.Rotation(Gf.Vec3d(0, 1, 0), 20.0 * i).GetQuat()) for i in range(count)]
        )
    )
    scatter.CreateScalesAttr([(1.0 + 0.1 * i, 1.0, 1.0 - 0.05 * i) for i in range(count)])
    scatter.CreateIdsAttr([10 + i for i in range(count)])
    scatter.CreateInvisibleIdsAttr([13])
    stage.Save()

    time = Usd.TimeCode(FRAME)
    cache = UsdGeom.XformCache(time)
    instancer_world = cache.GetLocalToWorldTransform(scatter.GetPrim())
    # Unmasked, so the list lines up with protoIndices; the mask is applied below.
    transforms = scatter.ComputeInstanceTransformsAtTime(
        time,
        time,
        UsdGeom.PointInstancer.IncludeProtoXform,
        UsdGeom.PointInstancer.IgnoreMask,
    )
    mask = scatter.ComputeMaskAtTime(time)
    proto_indices = scatter.GetProtoIndicesAttr().Get(time)
    instances = []
    for i, m in enumerate(transforms):
        if mask and not mask[i]:
            continue
        proto = ["Ball", "Rock"][proto_indices[i]]
        instances.append(
            {"prototype": proto, "instancer_from_proto": matrix_rows(m * instancer_world)}
        )
    # Meshes inside each prototype, relative to the prototype root (its own transform is
    # part of ComputeInstanceTransformsAtTime's answer).
    slab_in_rock = cache.GetLocalToWorldTransform(slab.GetPrim()) * cache.GetLocalToWorldTransform(
        rock.GetPrim()
    ).GetInverse()
    answers = {
        "frame": FRAME,
        "instances": instances,
        "rock_from_slab": matrix_rows(slab_in_rock),
    }
    (out / "instancer.json").write_text(json.dumps(answers, indent=1))


def implicit(out: Path) -> None:
    stage = new_stage(out / "implicit.usda")
    shapes = [
        ("Sphere", UsdGeom.Sphere, {"radius": 0.5}, (0, 0, 0)),
        ("Cube", UsdGeom.Cube, {"size": 1.2}, (2, 0, 0)),
        ("Cylinder", UsdGeom.Cylinder, {"radius": 0.3, "height": 1.0, "axis": "X"}, (4, 0, 0)),
        ("Cone", UsdGeom.Cone, {"radius": 0.4, "height": 0.8, "axis": "Z"}, (6, 0, 0)),
        ("Capsule", UsdGeom.Capsule, {"radius": 0.2, "height": 0.6, "axis": "Y"}, (8, 0, 0)),
        ("Plane", UsdGeom.Plane, {"width": 2.0, "length": 1.0, "axis": "Y"}, (10, 0, 0)),
    ]
    for name, schema, attrs, at in shapes:
        prim = schema.Define(stage, f"/World/{name}")
        for key, value in attrs.items():
            prim.GetPrim().GetAttribute(key).Set(value)
        prim.AddTranslateOp().Set(Gf.Vec3d(*at))
        # Extents as authoring tools write them.
        extent = schema.ComputeExtentFromPlugins(prim, Usd.TimeCode.Default())
        prim.CreateExtentAttr(extent)
    stage.Save()
    cache = UsdGeom.BBoxCache(Usd.TimeCode.Default(), [UsdGeom.Tokens.default_])
    bounds = {}
    for name, *_ in shapes:
        box = cache.ComputeWorldBound(stage.GetPrimAtPath(f"/World/{name}")).ComputeAlignedRange()
        bounds[f"/World/{name}"] = [list(box.GetMin()), list(box.GetMax())]
    (out / "implicit.json").write_text(json.dumps({"bounds": bounds}, indent=1, sort_keys=True))


def baked_skinning(out: Path) -> None:
    from pxr import UsdSkel

    source = out / "skinned.usdc"
    if not source.exists():
        print(f"{source} missing: run tools/blender/make_usd_skinning.py first", file=sys.stderr)
        return
    with tempfile.TemporaryDirectory() as tmp:
        copy = Path(tmp) / "skinned.usdc"
        shutil.copy(source, copy)
        stage = Usd.Stage.Open(str(copy))
        assert UsdSkel.BakeSkinning(stage.Traverse())
        answers = {}
        for frame in (1.0, 9.0, 17.0):
            time = Usd.TimeCode(frame)
            cache = UsdGeom.XformCache(time)
            for prim in stage.Traverse():
                if not prim.IsA(UsdGeom.Mesh):
                    continue
                world = cache.GetLocalToWorldTransform(prim)
                points = UsdGeom.Mesh(prim).GetPointsAttr().Get(time)
                answers.setdefault(str(prim.GetPath()), {})[str(int(frame))] = [
                    [round(c, 6) for c in world.Transform(Gf.Vec3d(p))] for p in points
                ]
    (out / "skinned_baked.json").write_text(json.dumps(answers))


def main() -> None:
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    assets(out)
    package(out)
    materials(out)
    prims(out)
    instancer(out)
    implicit(out)
    baked_skinning(out)


if __name__ == "__main__":
    main()
