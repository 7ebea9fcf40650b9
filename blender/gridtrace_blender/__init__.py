"""gridtrace for Blender: a render engine that exports the scene as USD, renders it with the
gridtrace command-line renderer and shows the result, passes, progress and partial images
in Blender. See the manual's Blender page (docs/manual/blender.md)."""

bl_info = {
    "name": "gridtrace",
    "author": "gridtrace",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Render Properties > Render Engine > gridtrace",
    "description": "Render with gridtrace, a physically based CPU path tracer",
    "category": "Render",
}

from . import engine, farm, properties, ui  # noqa: E402

MODULES = (properties, engine, farm, ui)


def register():
    for module in MODULES:
        module.register()


def unregister():
    for module in reversed(MODULES):
        module.unregister()
