"""The gridtrace panels in the Render properties."""

import bpy


class GRIDTRACE_PT_render(bpy.types.Panel):
    bl_label = "gridtrace"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"GRIDTRACE"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        settings = context.scene.gridtrace
        layout = self.layout
        layout.use_property_split = True
        for name in ("samples", "max_depth", "noise_threshold", "time_limit", "denoise", "pixel_filter",
                     "filter_width", "seed", "threads", "motion_steps", "update_seconds", "albedo_pass"):
            layout.prop(settings, name)
        layout.operator("gridtrace.write_farm_job", icon="NETWORK_DRIVE")


def _panels():
    """Blender's own panels that apply to gridtrace too (dimensions, output, colour
    management, motion blur, film transparency live in them)."""
    wanted = ("RENDER_PT_color_management", "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output",
              "DATA_PT_camera", "DATA_PT_camera_dof", "DATA_PT_lens", "RENDER_PT_motion_blur")
    return [getattr(bpy.types, name) for name in wanted if hasattr(bpy.types, name)]


def register():
    bpy.utils.register_class(GRIDTRACE_PT_render)
    for panel in _panels():
        if hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.add("GRIDTRACE")


def unregister():
    for panel in _panels():
        if hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.discard("GRIDTRACE")
    bpy.utils.unregister_class(GRIDTRACE_PT_render)
