"""The Blender add-on, tested headless with the PyPI `bpy` package (Blender as a Python
module). Run by tests/blender_addon.rs (so by tools/test.sh); by hand:

    python3 tools/blender/test_addon.py path/to/gridtrace

It builds the add-on's zip (tools/blender/build_addon.py), installs and enables it in a
throw-away Blender user folder, builds the bundled Cornell box in bpy, and checks:
- F12 (`render.render(write_still=True)`) at 64×64 equals a command-line render of the
  exported scene with the same settings, bit for bit, and so do the Depth, Normal and
  Denoising Albedo passes the CLI's AOVs;
- Render Animation over three frames of a moving box: three different images, each equal
  to a `--frame` render of the animation exported once;
- a render stopped after its first pass returns the partial image and leaves no gridtrace
  process and no temporary folder;
- a missing binary and a scene gridtrace refuses end in Blender reports, not exceptions;
- Blender's settings reach the command line: resolution percentage, camera, depth of
  field, motion blur, world colour, view transform, film transparency;
- "Write Slurm Job" writes the scene, the Slurm scripts and a submit.sh.
Prints one line per check; exits non-zero on the first failure.

    python3 tools/blender/test_addon.py path/to/gridtrace --references OUT SPP

renders the project's Blender reference scenes through the add-on instead, as Cycles'
references were made (tools/blender/make_references.py: two halves, seeds 1 and 2, box
filter, no world), into OUT/NAME_a.exr and OUT/NAME_b.exr, for tests/blender_addon.rs to
compare with tests/data/references/.
"""

import glob
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
WORK = tempfile.mkdtemp(prefix="gridtrace-addon-test-")
# The add-on's temporary folders go here, apart from any other run's.
tempfile.tempdir = os.path.join(WORK, "tmp")
os.makedirs(tempfile.tempdir)
# A Blender user folder of our own: installing the add-on touches nothing of the user's.
os.environ["BLENDER_USER_RESOURCES"] = os.path.join(WORK, "blender-user")
os.environ["BLENDER_USER_SCRIPTS"] = os.path.join(WORK, "blender-user", "scripts")

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import OpenEXR  # noqa: E402

sys.path.insert(0, HERE)
import build_addon  # noqa: E402
import make_cornell  # noqa: E402

GRIDTRACE = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else "gridtrace"
MODULE = "gridtrace_blender"


def check(condition, what):
    if not condition:
        print(f"FAILED: {what} (files kept in {WORK})")
        sys.exit(1)


def channels(path):
    """Every channel of an EXR (any part), by name, rows from the top."""
    out = {}
    with OpenEXR.File(path, separate_channels=True) as f:
        for part in f.parts:
            for name, channel in part.channels.items():
                out[name] = np.asarray(channel.pixels, dtype=np.float32)
    return out


def cli(argv, keep):
    """The add-on's last command run again on the kept export; returns the output's channels."""
    scene_file = os.path.join(keep, "scene.usdc")
    out = os.path.join(keep, "cli.exr")
    args = list(argv)
    args[1] = scene_file
    args[args.index("-o") + 1] = out
    # Progress and checkpoints change nothing in the image.
    for flag in ("--checkpoint", "--progress"):
        i = args.index(flag)
        del args[i:i + 2]
    subprocess.run(args, check=True, stderr=subprocess.DEVNULL)
    return channels(out)


def install():
    _, addon_zip = build_addon.build(os.path.join(WORK, "dist"))
    bpy.ops.preferences.addon_install(filepath=addon_zip)


def enable():
    """Enables the installed add-on (factory settings, which every test scene starts from,
    turn it off) and points it at the binary under test."""
    bpy.ops.preferences.addon_enable(module=MODULE)
    prefs = bpy.context.preferences.addons[MODULE].preferences
    prefs.binary = GRIDTRACE
    return prefs


def cornell(size=64, samples=8):
    scene = make_cornell.reset()
    enable()
    make_cornell.build_cornell_box(scene)
    scene.render.engine = "GRIDTRACE"
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.gridtrace.samples = samples
    scene.gridtrace.update_seconds = 0.25
    scene.render.image_settings.media_type = "MULTI_LAYER_IMAGE"
    scene.render.image_settings.color_depth = "32"
    return scene


def f12(scene, name, keep=None):
    """F12 with write_still; returns (the image's channels, the add-on's last run)."""
    run = sys.modules[MODULE + ".run"]
    if keep:
        os.environ[run.KEEP] = keep
    scene.render.filepath = os.path.join(WORK, name)
    # A render whose engine reported an error raises it in a script (in the interface it
    # is a report in the info area).
    raised = None
    try:
        bpy.ops.render.render(write_still=True)
    except RuntimeError as e:
        raised = str(e)
    os.environ.pop(run.KEEP, None)
    path = scene.render.filepath
    last = dict(run.LAST, raised=raised)
    return (channels(path) if os.path.exists(path) else None), last


def test_f12_and_passes():
    scene = cornell()
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = True
    scene.gridtrace.albedo_pass = True
    keep = os.path.join(WORK, "keep-f12")
    image, last = f12(scene, "f12.exr", keep)
    check(image is not None, f"F12 wrote no image: {last}")
    expected = cli(last["command"], keep)
    # Normals in Blender's Z-up world: gridtrace's (x, y, z) is Blender's (x, -z, y).
    expected["normal.-Z"] = -expected["normal.Z"]
    pairs = {"ViewLayer.Combined." + c: c for c in "RGBA"}
    pairs.update({"ViewLayer.Depth.Z": "depth.Z"})
    pairs.update({"ViewLayer.Normal.X": "normal.X", "ViewLayer.Normal.Y": "normal.-Z", "ViewLayer.Normal.Z": "normal.Y"})
    pairs.update({f"ViewLayer.Denoising Albedo.{c}": f"albedo.{c}" for c in "RGB"})
    for blender, ours in pairs.items():
        check(blender in image and ours in expected, f"missing {blender} or {ours}: {sorted(image)}")
        check(np.array_equal(image[blender], expected[ours]), f"{blender} differs from the CLI's {ours}")
    # The floor faces +Z and the ceiling -Z in Blender's world.
    up = image["ViewLayer.Normal.Z"]
    check(up.max() > 0.999 and up.min() < -0.999, f"normals along Z span {up.min()}..{up.max()}")
    check(image["ViewLayer.Combined.R"].mean() > 0.05, "the F12 image is dark")
    print(f"ok: F12 at 64x64 equals the CLI render bit for bit, passes included ({len(pairs)} channels)")


def test_animation():
    scene = cornell(samples=4)
    box = bpy.data.objects["ShortBox"]
    for frame, x in ((1, 0.35), (3, -0.1)):
        box.location.x = x
        box.keyframe_insert("location", frame=frame)
    scene.frame_start, scene.frame_end = 1, 3
    scene.render.filepath = os.path.join(WORK, "anim-####")
    bpy.ops.render.render(animation=True)
    run = sys.modules[MODULE + ".run"]
    frames = [channels(os.path.join(WORK, f"anim-{f:04d}.exr")) for f in (1, 2, 3)]
    # The animation exported once, rendered at each frame by the command line.
    folder = os.path.join(WORK, "keep-anim")
    os.makedirs(folder, exist_ok=True)
    scene.frame_set(1)
    run.export(scene, folder, (0.0, 2.0))
    argv = run.LAST["command"]
    for f, image in zip((1, 2, 3), frames):
        args = list(argv)
        args[args.index("--frame") + 1] = str(f)
        expected = cli(args, folder)
        for c in "RGBA":
            check(np.array_equal(image[f"ViewLayer.Combined.{c}"], expected[c]), f"frame {f} channel {c} differs")
    check(not np.array_equal(frames[0]["ViewLayer.Combined.R"], frames[2]["ViewLayer.Combined.R"]),
          "frames 1 and 3 are the same image")
    check(not np.array_equal(frames[1]["ViewLayer.Combined.R"], frames[2]["ViewLayer.Combined.R"]),
          "frames 2 and 3 are the same image")
    print("ok: three animation frames differ and equal --frame renders of the exported animation")


def test_cancel():
    scene = cornell(samples=100000)
    run = sys.modules[MODULE + ".run"]
    before = set(glob.glob(os.path.join(tempfile.gettempdir(), "gridtrace-blender-*")))
    check(not before, f"temporary folders before: {before}")
    # Esc, as soon as gridtrace has reported its first pass.
    run.should_stop = lambda engine: bool(run.LAST.get("passes"))
    try:
        image, last = f12(scene, "cancelled.exr")
    finally:
        run.should_stop = lambda engine: engine.test_break()
    check(image is not None and image["ViewLayer.Combined.R"].mean() > 0.01, f"no partial image: {last}")
    record = dict(line.split("=", 1) for line in last["record"].splitlines())
    start, end = (int(v) for v in record["samples"].split(".."))
    check(start == 0 and 1 <= end < 100000, f"samples {record['samples']}")
    # No child of this process (Blender) is left: gridtrace was waited for.
    running = subprocess.run(["pgrep", "-P", str(os.getpid())], capture_output=True, text=True).stdout.split()
    check(not running, f"a child process is left: {running}")
    after = set(glob.glob(os.path.join(tempfile.gettempdir(), "gridtrace-blender-*")))
    check(after == before, f"temporary folders left: {after - before}")
    print(f"ok: a render stopped after its first pass returns samples {record['samples']}, "
          "leaves no process and no temporary folder")


def test_errors():
    scene = cornell()
    prefs = bpy.context.preferences.addons[MODULE].preferences
    prefs.binary = os.path.join(WORK, "no-such-gridtrace")
    image, last = f12(scene, "missing.exr")
    prefs.binary = GRIDTRACE
    reports = last.get("reports", [])
    check(any(kind == "ERROR" and "was not found" in text for kind, text in reports), f"reports: {reports}")
    check("was not found" in (last["raised"] or ""), f"raised: {last['raised']}")
    # An image larger than gridtrace allows: its one-line error becomes the report.
    scene.render.resolution_x = scene.render.resolution_y = 20000
    image, last = f12(scene, "refused.exr")
    reports = last.get("reports", [])
    check(any(kind == "ERROR" and text.startswith("gridtrace error:") for kind, text in reports), f"{reports}")
    print(f"ok: a missing binary and a refused render are Blender reports ({reports[-1][1][:70]}…)")


def test_settings():
    scene = cornell()
    cam_data = bpy.data.cameras.new("Side Lens")
    cam = bpy.data.objects.new("Side Cam", cam_data)
    cam.location = (0.0, -3.5, 1.2)
    cam.rotation_euler = (1.5708, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam_data.dof.use_dof = True
    cam_data.dof.aperture_fstop = 2.8
    cam_data.dof.focus_distance = 3.25
    scene.render.resolution_percentage = 50
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 0.5
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    world = bpy.data.worlds.new("Sky")
    world.color = (0.25, 0.5, 0.75)
    scene.world = world
    # A point lamp with its Soft Falloff off, which the USD export cannot say.
    bulb = bpy.data.lights.new("Bulb", "POINT")
    bulb.shadow_soft_size = 0.1
    bulb.use_soft_falloff = False
    bulb_object = bpy.data.objects.new("Bulb", bulb)
    bulb_object.location = (0.0, 0.0, 1.5)
    scene.collection.objects.link(bulb_object)
    keep = os.path.join(WORK, "keep-settings")
    image, last = f12(scene, "settings.exr", keep)
    argv = last["command"]
    text = " ".join(argv)
    for expected in ("--width 32 --height 32", "--camera /root/Side_Cam/Side_Lens", "--fstop 2.8",
                     "--focus-distance 3.25", "--shutter=-0.25..0.25", "--hide-environment",
                     "--view-transform standard", "--soft-falloff off"):
        check(expected in text, f"'{expected}' not in {text}")
    domes = glob.glob(os.path.join(keep, "textures", "color_*.exr"))
    check(len(domes) == 1, f"world colour textures: {domes}")
    check(image is not None and image["ViewLayer.Combined.A"].min() < 1, "film transparency left no alpha")
    print("ok: resolution %, camera, depth of field, motion blur, world, view transform, transparency "
          "and Soft Falloff reach gridtrace")


def test_farm():
    scene = cornell()
    folder = os.path.join(WORK, "farm")
    result = bpy.ops.gridtrace.write_farm_job(directory=folder, tasks=3)
    check("FINISHED" in result, f"write_farm_job: {result}")
    for name in ("scene.usdc", "submit.sh", "slurm/submit.sh", "slurm/render-part.sbatch", "slurm/merge.sbatch"):
        check(os.path.isfile(os.path.join(folder, name)), f"the farm folder lacks {name}")
    with open(os.path.join(folder, "submit.sh")) as f:
        script = f.read()
    check("slurm/submit.sh --tasks 3 --spp 8 scene.usdc render-0001.exr --frame 1" in script, script)
    print("ok: Write Slurm Job writes the scene, the Slurm scripts and submit.sh")


# The reference scenes rendered through the add-on: the Cornell box, Principled metals and
# plastics (tools/blender/make_principled.py), and from make_lighting.py Blender's lamps, an
# HDR world and a camera's depth of field (whose references keep the world).
REFERENCE_SCENES = ("cornell_box", "principled_metals", "principled_plastics", "lighting_lamps", "lighting_hdr",
                    "lighting_dof")


def render_references(out, spp):
    import make_lighting
    import make_principled
    import make_references

    builders = {name: entry[0] for name, entry in make_references.SCENE_TABLE.items()}
    builders.update({name: entry[0] for name, entry in make_principled.SCENE_TABLE.items()})
    builders.update({name: entry[0] for name, entry in make_lighting.SCENE_TABLE.items()})
    for name in REFERENCE_SCENES:
        scene = make_cornell.reset()
        enable()
        builders[name](scene)
        if not name.startswith("lighting_"):
            scene.world = None
        scene.render.engine = "GRIDTRACE"
        scene.render.resolution_x = scene.render.resolution_y = make_references.SIZE
        scene.render.resolution_percentage = 100
        scene.render.film_transparent = False
        scene.render.image_settings.file_format = "OPEN_EXR"
        scene.render.image_settings.color_depth = "32"
        scene.render.image_settings.color_mode = "RGB"
        scene.gridtrace.samples = spp // 2
        scene.gridtrace.pixel_filter = "BOX"
        scene.gridtrace.filter_width = 1.0
        for half, seed in (("a", 1), ("b", 2)):
            scene.gridtrace.seed = seed
            scene.render.filepath = os.path.join(out, f"{name}_{half}.exr")
            bpy.ops.render.render(write_still=True)
            check(os.path.isfile(scene.render.filepath), f"{name}: no image")
        print(f"ok: rendered {name} through the add-on at {spp} spp")


def main():
    install()
    if "--references" in sys.argv:
        at = sys.argv.index("--references")
        render_references(os.path.abspath(sys.argv[at + 1]), int(sys.argv[at + 2]))
        shutil.rmtree(WORK)
        return
    test_f12_and_passes()
    test_animation()
    test_cancel()
    test_errors()
    test_settings()
    test_farm()
    bpy.ops.preferences.addon_disable(module=MODULE)
    shutil.rmtree(WORK)
    print("all add-on checks passed")


if __name__ == "__main__":
    main()
