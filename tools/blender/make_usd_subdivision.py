"""Blender's Subdivision modifier through its USD exporter, twice: as the cage with
`subdivisionScheme = "catmullClark"` (the exporter's default, "Best Match"), and with the
modifier applied at its render level (Blender's own OpenSubdiv refinement, limit surface
on). gridtrace refines the first; `tests/usd_pipeline.rs` compares it with the second.

    /tmp/bpyenv/bin/python tools/blender/make_usd_subdivision.py tests/data/scenes/usd_pipeline

Objects (seen by a camera, lit by a sun): a cube (every vertex of valence 3), a capped cylinder (n-gon caps, valence 3 and
4), a grid with an open boundary (corners kept, as USD's edgeAndCorner default), and a
creased cube (its top face's edges creased 1, one vertical edge 0.5, one bottom vertex
creased 1; exported as creaseSharpnesses 10·c² and cornerSharpnesses 10), each with a
Subdivision modifier at Blender's defaults (render level 2).
"""

import math
import os
import sys

import bpy


def subdivided(obj):
    # Smooth shading, as subdivision surfaces are modelled: a flat-shaded object keeps its
    # facets through Blender's modifier, while a USD subdivision surface is smooth.
    bpy.ops.object.shade_smooth()
    modifier = obj.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels = 1
    modifier.render_levels = 2
    return obj


def crease_edges(mesh):
    """Creases 1 on the top face's edges, 0.5 on one vertical edge, 1 on one bottom vertex."""
    edge_crease = mesh.attributes.new("crease_edge", "FLOAT", "EDGE")
    vertex_crease = mesh.attributes.new("crease_vert", "FLOAT", "POINT")
    top = {v.index for v in mesh.vertices if v.co.z > 0.0}
    for edge in mesh.edges:
        a, b = edge.vertices
        if a in top and b in top:
            edge_crease.data[edge.index].value = 1.0
        elif {a, b} & top and mesh.vertices[a].co.x > 0.0 and mesh.vertices[b].co.x > 0.0 \
                and mesh.vertices[a].co.y > 0.0 and mesh.vertices[b].co.y > 0.0:
            edge_crease.data[edge.index].value = 0.5
    bottom_corner = min(mesh.vertices, key=lambda v: (v.co.z, v.co.x, v.co.y))
    vertex_crease.data[bottom_corner.index].value = 1.0


def build():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-1.5, 0.0, 0.5))
    subdivided(bpy.context.active_object).name = "Cube"
    bpy.ops.mesh.primitive_cylinder_add(vertices=8, radius=0.5, depth=1.0, location=(0.0, 0.0, 0.5))
    subdivided(bpy.context.active_object).name = "Cylinder"
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=3, y_subdivisions=3, size=1.0, location=(1.5, 0.0, 0.2))
    grid = subdivided(bpy.context.active_object)
    grid.name = "Grid"
    grid.data.vertices[4].co.z = 0.4
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 1.5, 0.5))
    creased = subdivided(bpy.context.active_object)
    creased.name = "CreasedCube"
    crease_edges(creased.data)
    bpy.ops.object.camera_add(location=(0.0, -6.0, 3.0), rotation=(math.radians(65), 0.0, 0.0))
    bpy.context.scene.camera = bpy.context.active_object
    bpy.ops.object.light_add(type="SUN", rotation=(math.radians(35), math.radians(25), 0.0))
    bpy.context.active_object.data.energy = 3.0


def main():
    out = sys.argv[-1]
    build()
    for name, mode in (("subdivision_cage", "BEST_MATCH"), ("subdivision_applied", "TESSELLATE")):
        path = os.path.join(out, f"{name}.usda")
        bpy.ops.wm.usd_export(
            filepath=path,
            export_subdivision=mode,
            evaluation_mode="RENDER",
            export_materials=False,
        )
        print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main()
