"""The full Stanford dragon (`tools/dev/fetch-dragon.sh`) as the formats users bring, for
the load-time benchmark: `data/dragon/dragon.glb` written by trimesh and
`data/dragon/dragon.usdc` written by usd-core (a UsdGeom.Mesh of triangles), beside the
PLY itself.

    python tools/dev/make_dragon_formats.py   # needs trimesh and usd-core
"""

import gzip
import io
import pathlib

import numpy as np
import trimesh
from pxr import Usd, UsdGeom, Vt

DRAGON = pathlib.Path(__file__).resolve().parents[2] / "data" / "dragon"


def main():
    with gzip.open(DRAGON / "dragon_vrip.ply.gz", "rb") as f:
        mesh = trimesh.load(io.BytesIO(f.read()), file_type="ply", process=False)
    (DRAGON / "dragon.ply").write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="binary"))
    mesh.export(DRAGON / "dragon.glb")
    stage = Usd.Stage.CreateNew(str(DRAGON / "dragon.usdc"))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    prim = UsdGeom.Mesh.Define(stage, "/Dragon")
    prim.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(mesh.vertices, dtype=np.float32)))
    prim.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(mesh.faces), 3, dtype=np.int32)))
    prim.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(np.asarray(mesh.faces, dtype=np.int32).ravel()))
    prim.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    stage.SetDefaultPrim(prim.GetPrim())
    stage.Save()
    for name in ("dragon.ply", "dragon.glb", "dragon.usdc"):
        print(f"{name}: {(DRAGON / name).stat().st_size / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
