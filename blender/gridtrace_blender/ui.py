"""The gridtrace panels: sampling and the rest of gridtrace's own settings, motion blur and
film in the Render properties, passes in the View Layer properties (Blender shows its own
panels for these only to its own engines)."""

import bpy


class GridtracePanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"GRIDTRACE"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class GRIDTRACE_PT_render(GridtracePanel, bpy.types.Panel):
    bl_label = "gridtrace"
    # The settings it shows, in order.
    SHOWN = ("samples", "max_depth", "noise_threshold", "time_limit", "denoise", "pixel_filter", "filter_width",
             "seed", "threads", "update_seconds")

    def draw(self, context):
        settings = context.scene.gridtrace
        layout = self.layout
        layout.use_property_split = True
        for name in self.SHOWN:
            layout.prop(settings, name)
        layout.operator("gridtrace.write_farm_job", icon="NETWORK_DRIVE")


class GRIDTRACE_PT_motion_blur(GridtracePanel, bpy.types.Panel):
    bl_label = "Motion Blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.render, "use_motion_blur", text="")

    def draw(self, context):
        render = context.scene.render
        layout = self.layout
        layout.use_property_split = True
        layout.active = render.use_motion_blur
        layout.prop(render, "motion_blur_position", text="Position")
        layout.prop(render, "motion_blur_shutter")
        layout.prop(context.scene.gridtrace, "motion_steps")


class GRIDTRACE_PT_film(GridtracePanel, bpy.types.Panel):
    bl_label = "Film"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.prop(context.scene.render, "film_transparent")


class GRIDTRACE_PT_passes(GridtracePanel, bpy.types.Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        view_layer = context.view_layer
        layout.prop(view_layer, "use_pass_z")
        layout.prop(view_layer, "use_pass_normal")
        layout.prop(view_layer, "use_pass_position")
        layout.prop(context.scene.gridtrace, "albedo_pass")


CLASSES = (GRIDTRACE_PT_render, GRIDTRACE_PT_motion_blur, GRIDTRACE_PT_film, GRIDTRACE_PT_passes)


def _panels():
    """Blender's own panels that apply to gridtrace too."""
    wanted = ("RENDER_PT_color_management", "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_output",
              "DATA_PT_camera", "DATA_PT_camera_dof", "DATA_PT_camera_dof_aperture", "DATA_PT_lens",
              "DATA_PT_light", "DATA_PT_context_light", "DATA_PT_EEVEE_light", "WORLD_PT_context_world")
    return [getattr(bpy.types, name) for name in wanted if hasattr(bpy.types, name)]


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    for panel in _panels():
        if hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.add("GRIDTRACE")


def unregister():
    for panel in _panels():
        if hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.discard("GRIDTRACE")
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
