"""One render through gridtrace: the evaluated scene exported as USD into a temporary
folder, gridtrace run on it with Blender's settings, its progress and partial images shown,
its result copied into Blender's render result. The folder is removed afterwards."""

import ctypes
import json
import os
import queue
import shutil
import signal
import subprocess
import tempfile
import threading
import time

import bpy
import numpy as np

from . import command, exr, passes
from .properties import preferences


# The last render's command, record and reports, for scripts and tests that check what ran.
LAST = {}

# Set GRIDTRACE_BLENDER_KEEP to a folder to keep a copy of each exported scene there (to
# render it again from the command line, or to send with a bug report).
KEEP = "GRIDTRACE_BLENDER_KEEP"


def should_stop(engine):
    """True once Blender asks the render to stop (Esc)."""
    return engine.test_break()


class RenderFailed(Exception):
    """A render that could not be done: the message is for Blender's report."""


def binary_path(context):
    """The gridtrace program: the preferences' path, else `gridtrace` on PATH."""
    prefs = preferences(context)
    configured = prefs.binary if prefs else ""
    configured = bpy.path.abspath(configured) if configured else ""
    found = configured if configured else shutil.which("gridtrace")
    if not found or not os.access(found, os.X_OK):
        where = f"'{configured}'" if configured else "'gridtrace' on PATH"
        raise RenderFailed(f"gridtrace: the program {where} was not found; set its path in the add-on's preferences")
    return found


def read_settings(scene, view_layer, keys):
    """The plain values command.build takes, from the scene."""
    r, g = scene.render, scene.gridtrace
    width, height = command.size(r.resolution_x, r.resolution_y, r.resolution_percentage)
    camera = scene.camera
    if camera is None or camera.type != "CAMERA":
        raise RenderFailed("gridtrace: the scene has no active camera")
    dof = None
    if camera.data.dof.use_dof:
        focus = camera.data.dof.focus_distance
        target = camera.data.dof.focus_object
        if target is not None:
            view = camera.matrix_world.to_3x3().col[2].normalized()
            focus = abs((target.matrix_world.translation - camera.matrix_world.translation).dot(view))
        dof = (camera.data.dof.aperture_fstop, focus)
    return {
        "width": width,
        "height": height,
        "frame": scene.frame_current + scene.frame_subframe,
        "camera": command.camera_path(camera.name, camera.data.name),
        "samples": g.samples,
        "max_depth": g.max_depth,
        "seed": g.seed,
        "threads": g.threads,
        "filter": g.pixel_filter,
        "filter_width": g.filter_width,
        "noise_threshold": g.noise_threshold,
        "time_limit": g.time_limit,
        "denoise": g.denoise,
        "dof": dof,
        "shutter": command.shutter(r.motion_blur_shutter, r.motion_blur_position) if r.use_motion_blur else None,
        "motion_steps": g.motion_steps,
        "transparent": r.film_transparent,
        "view_transform": scene.view_settings.view_transform,
        # Blender applies exposure and the view transform to the linear result it shows
        # and saves: passing the exposure too would apply it twice.
        "exposure": None,
        "aovs": passes.aov_layers(keys),
        "checkpoint": g.update_seconds,
        "progress": True,
        "soft_falloff": soft_falloff(scene),
    }


def soft_falloff(scene):
    """False when the scene's point and spot lamps with a radius all have Soft Falloff
    turned off: the USD export does not say, and gridtrace assumes Blender's default (on)."""
    lamps = [o.data for o in scene.objects
             if o.type == "LIGHT" and o.data.type in {"POINT", "SPOT"} and o.data.shadow_soft_size > 0]
    return not lamps or any(lamp.use_soft_falloff for lamp in lamps)


def export(scene, folder, shutter):
    """Writes the scene as Blender's USD exporter does, with what gridtrace reads: lights,
    cameras, the world as a dome light, and glass through the MaterialX network. The frames
    around the current one (and the shutter) are written as time samples, which gridtrace
    reads at `--frame`: the exporter evaluates each frame itself, so what is written does not
    depend on which frame Blender's own scene was last evaluated at (during Render
    Animation it is not the frame being rendered)."""
    path = os.path.join(folder, "scene.usdc")
    kept = (scene.frame_start, scene.frame_end)
    shutter = shutter or (0.0, 0.0)
    try:
        scene.frame_start = int(np.floor(scene.frame_current + shutter[0])) - 1
        scene.frame_end = int(np.ceil(scene.frame_current + shutter[1])) + 1
        result = _run_exporter(
            filepath=path, selected_objects_only=False, export_animation=True,
            export_materials=True, generate_preview_surface=True, generate_materialx_network=True,
            export_lights=True, export_cameras=True, convert_world_material=True, evaluation_mode="RENDER",
            export_textures_mode="NEW", relative_paths=True, export_subdivision="BEST_MATCH")
    finally:
        scene.frame_start, scene.frame_end = kept
    if "FINISHED" not in result or not os.path.isfile(path):
        raise RenderFailed("gridtrace: Blender's USD exporter did not write the scene")
    return path


def _run_exporter(**options):
    """Blender's USD exporter. From a render started in Blender's interface the context may
    lack a window, which the operator's poll wants: then it runs again with the first
    window put in the context. Any failure is a report, never an exception."""
    try:
        return bpy.ops.wm.usd_export(**options)
    except RuntimeError as first:
        windows = bpy.context.window_manager.windows if bpy.context.window_manager else []
        if bpy.app.background or not windows:
            raise RenderFailed(f"gridtrace: Blender's USD exporter failed: {first}") from first
        try:
            with bpy.context.temp_override(window=windows[0]):
                return bpy.ops.wm.usd_export(**options)
        except RuntimeError as second:
            raise RenderFailed(f"gridtrace: Blender's USD exporter failed: {second}") from second


def _die_with_parent():
    """In the child before exec: SIGTERM when Blender goes away (Linux), so no gridtrace
    outlives it; SIGTERM makes gridtrace write what it has and quit."""
    try:
        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _lines(stream, into):
    for line in stream:
        into.put(line.rstrip("\n"))
    into.put(None)


def run(engine, argv, output, on_progress, on_partial):
    """Runs gridtrace; calls on_progress(fraction) and on_partial(path) as it renders;
    stops it as Ctrl-C does when Blender asks to. Returns (exit code, stderr lines)."""
    process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True, errors="replace", preexec_fn=_die_with_parent if os.name == "posix" else None)
    lines, said = queue.Queue(), []
    reader = threading.Thread(target=_lines, args=(process.stderr, lines), daemon=True)
    reader.start()
    stopped, seen = False, None
    try:
        while True:
            try:
                line = lines.get(timeout=0.1)
            except queue.Empty:
                line = ""
            if line is None:
                break
            if line.startswith("{"):
                try:
                    state = json.loads(line)
                    LAST.setdefault("passes", []).append(state["pass"])
                    on_progress(state["pass"] / max(1, state["of"]))
                except (ValueError, KeyError):
                    said.append(line)
            elif line:
                said.append(line)
            if not stopped and should_stop(engine):
                process.send_signal(signal.SIGINT)
                stopped = True
            try:
                stamp = os.stat(output).st_mtime_ns
            except OSError:
                stamp = None
            if stamp is not None and stamp != seen and process.poll() is None:
                seen = stamp
                on_partial(output)
        code = process.wait()
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        reader.join(timeout=5)
    return code, said


def fill(result, planes, keys, width, height, combined_only=False):
    """Copies gridtrace's channels into the render result's passes (Blender's rows run
    bottom to top)."""
    layer = result.layers[0]

    def put(name, channels, world_space=False):
        target = layer.passes.find_by_name(name, layer.name) if hasattr(layer.passes, "find_by_name") else None
        if target is None:
            target = layer.passes.get(name)
        if target is None or any(c not in planes for c in channels):
            return
        values = [planes[c][::-1, :] for c in channels]
        if world_space:
            values = list(passes.to_blender_axes(*values))
        data = np.stack(values, axis=-1).reshape(-1, len(channels))
        target.rect.foreach_set(np.ascontiguousarray(data, dtype=np.float32).ravel())

    put("Combined", passes.COMBINED)
    if not combined_only:
        for key in keys:
            name, _, _, _, _, channels = passes.PASSES[key]
            put(name, channels, key in passes.IN_WORLD_SPACE)


def render(engine, depsgraph):
    """F12 for one frame."""
    scene = depsgraph.scene
    view_layer = depsgraph.view_layer
    keys = passes.wanted(scene, view_layer)
    binary = binary_path(bpy.context)
    settings = read_settings(scene, view_layer, keys)
    width, height = settings["width"], settings["height"]
    with tempfile.TemporaryDirectory(prefix="gridtrace-blender-") as folder:
        engine.update_stats("gridtrace", "exporting the scene")
        scene_file = export(scene, folder, settings["shutter"])
        if os.environ.get(KEEP):
            shutil.copytree(folder, os.environ[KEEP], dirs_exist_ok=True)
        output = os.path.join(folder, "render.exr")
        argv = command.build(binary, scene_file, output, settings)
        LAST["command"] = argv
        for key in keys:
            name, channels, chan_id, _, _, _ = passes.PASSES[key]
            engine.add_pass(name, channels, chan_id)
        result = engine.begin_result(0, 0, width, height)
        engine.update_stats("gridtrace", "rendering")

        def partial(path):
            try:
                fill(result, exr.read(path), keys, width, height, combined_only=True)
                engine.update_result(result)
            except (OSError, exr.ExrError, ValueError):
                pass  # a later update or the end will show it

        started = time.monotonic()
        code, said = run(engine, argv, output, engine.update_progress, partial)
        for line in said:
            if line.startswith("warning:"):
                engine.say({"WARNING"}, "gridtrace " + line)
            elif line.startswith("note:"):
                engine.say({"INFO"}, "gridtrace " + line)
        if not os.path.isfile(output):
            engine.end_result(result, cancel=True)
            errors = [line for line in said if line.startswith("error:")]
            raise RenderFailed("gridtrace " + (errors[0] if errors else f"exited with status {code} and wrote no image"))
        fill(result, exr.read(output), keys, width, height)
        LAST["record"] = exr.text_attribute(output, "gridtrace/record")
        engine.end_result(result)
        engine.update_stats("gridtrace", f"rendered in {time.monotonic() - started:.2f} s")
