"""Blender's settings as gridtrace's command line: what a user set in Blender reaches the
renderer without being typed again. Pure functions of plain values, so they can be tested
without rendering."""

import re

# Blender's pixel filters that gridtrace has (Cycles' names and widths).
FILTERS = {"BOX": "box", "GAUSSIAN": "gaussian", "BLACKMAN_HARRIS": "blackman-harris"}


def usd_name(name):
    """A Blender name as its USD exporter writes it into a prim path: characters USD does
    not allow become `_`, and a leading digit gets one in front."""
    safe = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return "_" + safe if not safe or safe[0].isdigit() else safe


def camera_path(object_name, data_name, root="/root"):
    """The prim path of a camera the USD exporter writes: the object's Xform, then the
    camera data."""
    return f"{root}/{usd_name(object_name)}/{usd_name(data_name)}"


def shutter(shutter_fraction, position):
    """Blender's motion blur shutter (a fraction of a frame) placed as its `position`
    (CENTER, START, END) says, in frames relative to the frame rendered."""
    if position == "START":
        return 0.0, shutter_fraction
    if position == "END":
        return -shutter_fraction, 0.0
    return -shutter_fraction / 2, shutter_fraction / 2


def size(resolution_x, resolution_y, percentage):
    """The image size a render of this resolution and percentage has (at least 1×1)."""
    return (max(1, resolution_x * percentage // 100), max(1, resolution_y * percentage // 100))


def build(binary, scene_file, output, settings):
    """The gridtrace command for `settings`, a dict of plain values (see engine.read_settings):
    width, height, frame, camera, samples, max_depth, seed, threads, filter, filter_width,
    noise_threshold, time_limit, denoise, dof (None or (fstop, focus distance)),
    shutter (None or (open, close)), motion_steps, transparent, view_transform,
    exposure (None: Blender applies it to the linear result), aovs (list), checkpoint,
    progress, soft_falloff (False: every lamp with a radius has Blender's Soft Falloff off)."""
    s = settings
    args = [binary, scene_file, "-o", output, "--width", str(s["width"]), "--height", str(s["height"])]
    args += ["--frame", _number(s["frame"])]
    if s.get("camera"):
        args += ["--camera", s["camera"]]
    if s.get("time_limit"):
        args += ["--time-limit", _number(s["time_limit"])]
        if s.get("samples"):
            args += ["--spp", str(s["samples"])]
    else:
        args += ["--spp", str(s["samples"])]
    args += ["--max-depth", str(s["max_depth"]), "--seed", str(s["seed"])]
    if s.get("threads"):
        args += ["--threads", str(s["threads"])]
    args += ["--filter", FILTERS.get(s["filter"], "box"), "--filter-width", _number(s["filter_width"])]
    if s.get("noise_threshold"):
        args += ["--noise-threshold", _number(s["noise_threshold"])]
    if s.get("denoise"):
        args += ["--denoise"]
    dof = s.get("dof")
    if dof is None:
        args += ["--fstop", "0"]
    else:
        args += ["--fstop", _number(dof[0]), "--focus-distance", _number(dof[1])]
    if s.get("shutter") is None:
        args += ["--shutter", "0..0"]
    else:
        open_, close = s["shutter"]
        args += [f"--shutter={_number(open_)}..{_number(close)}", "--motion-steps", str(s.get("motion_steps", 5))]
    if s.get("transparent"):
        args += ["--hide-environment"]
    args += ["--view-transform", "agx" if s.get("view_transform") == "AgX" else "standard"]
    if s.get("exposure"):
        args += ["--exposure", _number(s["exposure"])]
    if s.get("aovs"):
        args += ["--aov", ",".join(s["aovs"])]
    if s.get("checkpoint"):
        args += ["--checkpoint", _number(s["checkpoint"])]
    if s.get("progress"):
        args += ["--progress", "json"]
    if s.get("soft_falloff") is False:
        args += ["--soft-falloff", "off"]
    return args


def _number(value):
    """A number as the command line takes it: integers without a decimal point, others to
    the seven significant digits a Blender (32-bit) float holds."""
    value = float(value)
    return str(int(value)) if value == int(value) else format(value, ".7g")
