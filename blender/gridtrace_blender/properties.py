"""What is gridtrace's own in Blender: its render settings (a panel in the Render
properties) and the add-on's preferences (where the binary is)."""

import bpy

ADDON = __package__


class GridtraceSettings(bpy.types.PropertyGroup):
    """Scene settings that Blender itself has no place for."""

    samples: bpy.props.IntProperty(
        name="Samples", description="Samples per pixel (with a time limit, the most)", default=64, min=1, soft_max=4096)
    max_depth: bpy.props.IntProperty(
        name="Max Bounces", description="Most bounces per path; 0 shows emitters only", default=16, min=0, max=1024)
    noise_threshold: bpy.props.FloatProperty(
        name="Noise Threshold",
        description="Adaptive sampling: a pixel stops below this estimated error (0: off)",
        default=0.0, min=0.0, max=1.0, precision=4)
    time_limit: bpy.props.FloatProperty(
        name="Time Limit", description="Render passes until this many seconds have passed (0: no limit)",
        default=0.0, min=0.0, subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE")
    denoise: bpy.props.BoolProperty(
        name="Denoise", description="Denoise with Intel Open Image Denoise (needs the OIDN 2 library)", default=False)
    pixel_filter: bpy.props.EnumProperty(
        name="Pixel Filter",
        items=[("BOX", "Box", "Uniform over the pixel"),
               ("GAUSSIAN", "Gaussian", "Gaussian, sigma = width / 4"),
               ("BLACKMAN_HARRIS", "Blackman-Harris", "Cycles' default filter")],
        default="BOX")
    filter_width: bpy.props.FloatProperty(
        name="Filter Width", description="The pixel filter's width in pixels", default=1.0, min=1 / 64, max=16.0)
    seed: bpy.props.IntProperty(name="Seed", description="The same seed gives the same image", default=0, min=0)
    threads: bpy.props.IntProperty(name="Threads", description="Worker threads (0: one per core)", default=0, min=0)
    albedo_pass: bpy.props.BoolProperty(
        name="Denoising Albedo", description="Write the Denoising Albedo pass", default=False)
    motion_steps: bpy.props.IntProperty(
        name="Motion Steps", description="Instants across the shutter at which the scene is read", default=5, min=2,
        max=64)
    update_seconds: bpy.props.FloatProperty(
        name="Update Every", description="Seconds between updates of the image while it renders", default=2.0,
        min=0.25, max=3600.0)


class GridtracePreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    binary: bpy.props.StringProperty(
        name="gridtrace binary", description="The gridtrace program (empty: 'gridtrace' on PATH)", default="",
        subtype="FILE_PATH")

    def draw(self, context):
        self.layout.prop(self, "binary")


def preferences(context):
    """The add-on's preferences, or None when it is not installed as an add-on."""
    addon = context.preferences.addons.get(ADDON)
    return addon.preferences if addon else None


CLASSES = (GridtraceSettings, GridtracePreferences)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.gridtrace = bpy.props.PointerProperty(type=GridtraceSettings)


def unregister():
    del bpy.types.Scene.gridtrace
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
