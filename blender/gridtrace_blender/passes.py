"""The render passes gridtrace fills in Blender, and the EXR channels each comes from."""

# (Blender pass, channels, channel ids, kind, gridtrace --aov layer, EXR channel names)
PASSES = {
    "depth": ("Depth", 1, "Z", "VALUE", "depth", ["depth.Z"]),
    "normal": ("Normal", 3, "XYZ", "VECTOR", "normal", ["normal.X", "normal.Y", "normal.Z"]),
    "position": ("Position", 3, "XYZ", "VECTOR", "position", ["position.X", "position.Y", "position.Z"]),
    "albedo": ("Denoising Albedo", 3, "RGB", "COLOR", "albedo", ["albedo.R", "albedo.G", "albedo.B"]),
    "noisy": ("Noisy Image", 4, "RGBA", "COLOR", None, ["noisy.R", "noisy.G", "noisy.B", "noisy.A"]),
}

COMBINED = ["R", "G", "B", "A"]

# Passes holding directions or points: gridtrace works Y-up (the exported stage's Z-up
# turned as USD's upAxis says), Blender's world is Z-up; Blender (x, y, z) is gridtrace
# (x, z, -y), so gridtrace's (x, y, z) is Blender's (x, -z, y).
IN_WORLD_SPACE = {"normal", "position"}


def to_blender_axes(x, y, z):
    """A direction or point of gridtrace's world in Blender's."""
    return x, -z, y


def wanted(scene, view_layer):
    """The keys of PASSES this view layer asks for: Blender's own toggles (Z, Normal,
    Position), the add-on's Denoising Albedo, and Noisy Image when denoising."""
    keys = []
    if getattr(view_layer, "use_pass_z", False):
        keys.append("depth")
    if getattr(view_layer, "use_pass_normal", False):
        keys.append("normal")
    if getattr(view_layer, "use_pass_position", False):
        keys.append("position")
    settings = scene.gridtrace
    if settings.albedo_pass:
        keys.append("albedo")
    if settings.denoise:
        keys.append("noisy")
    return keys


def aov_layers(keys):
    """The `--aov` layers the passes need."""
    return [PASSES[k][4] for k in keys if PASSES[k][4]]
