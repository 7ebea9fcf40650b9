"""gridtrace as a Blender render engine: F12 and Render Animation run it on the exported
scene; its passes, progress and partial images appear in Blender."""

import bpy

from . import passes, run


class GridtraceRenderEngine(bpy.types.RenderEngine):
    bl_idname = "GRIDTRACE"
    bl_label = "gridtrace"
    bl_use_preview = False
    bl_use_postprocess = True

    def render(self, depsgraph):
        run.LAST.clear()
        try:
            run.render(self, depsgraph)
        except run.RenderFailed as e:
            self.say({"ERROR"}, str(e))
        except Exception as e:  # noqa: BLE001 - Blender must get a report, not a traceback
            self.say({"ERROR"}, f"gridtrace: the add-on failed: {e}")

    def say(self, kind, message):
        """Reports `message` in Blender's info area, and keeps it for scripts."""
        run.LAST.setdefault("reports", []).append((next(iter(kind)), message))
        self.report(kind, message)

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for key in passes.wanted(scene, renderlayer):
            name, channels, chan_id, kind, _, _ = passes.PASSES[key]
            self.register_pass(scene, renderlayer, name, channels, chan_id, kind)


def register():
    bpy.utils.register_class(GridtraceRenderEngine)


def unregister():
    bpy.utils.unregister_class(GridtraceRenderEngine)
