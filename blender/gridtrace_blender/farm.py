"""A Slurm job for the farm, written from Blender: the exported scene, the project's Slurm
scripts, and one `submit.sh` that submits the image (split into sample ranges, merged at
the end) or every frame of the scene's range, with the scene's settings."""

import os
import shlex
import shutil

import bpy

from . import command, run

SLURM_FILES = ("submit.sh", "render-part.sbatch", "merge.sbatch")


def slurm_scripts():
    """Where the Slurm scripts are: inside the installed add-on, or in the repository."""
    here = os.path.dirname(os.path.abspath(__file__))
    for folder in (os.path.join(here, "slurm"), os.path.join(here, "..", "..", "tools", "user", "slurm")):
        if all(os.path.isfile(os.path.join(folder, f)) for f in SLURM_FILES):
            return folder
    raise run.RenderFailed("gridtrace: the add-on's Slurm scripts are missing; reinstall it")


def job_script(settings, tasks, frames):
    """The job's submit.sh: one submission per frame, each split into `tasks` sample ranges."""
    options = command.build("gridtrace", "scene.usdc", "render.exr", settings)
    # What submit.sh sets itself, and what only a render inside Blender needs.
    drop_with_value = {"-o", "--spp", "--frame", "--checkpoint", "--progress"}
    kept, skip = [], False
    for arg in options[2:]:
        if skip:
            skip = False
        elif arg in drop_with_value:
            skip = True
        else:
            kept.append(arg)
    lines = [
        "#!/usr/bin/env bash",
        "# Written by gridtrace's Blender add-on: submits the render to Slurm.",
        "# Run it on the cluster from this folder; GRIDTRACE names the binary if it is not on PATH.",
        "set -euo pipefail",
        'cd "$(dirname "$0")"',
    ]
    for frame in frames:
        out = f"render-{frame:04d}.exr"
        call = ["slurm/submit.sh", "--tasks", str(tasks), "--spp", str(settings["samples"]), "scene.usdc", out,
                "--frame", str(frame)] + kept
        lines.append(" ".join(shlex.quote(a) for a in call))
    return "\n".join(lines) + "\n"


class GRIDTRACE_OT_write_farm_job(bpy.types.Operator):
    """Write the scene and a Slurm job that renders it on a cluster"""

    bl_idname = "gridtrace.write_farm_job"
    bl_label = "Write Slurm Job"

    directory: bpy.props.StringProperty(subtype="DIR_PATH")
    tasks: bpy.props.IntProperty(name="Tasks per Frame", default=4, min=1, max=4096)
    animation: bpy.props.BoolProperty(name="Frame Range", description="Every frame of the scene's range", default=False)

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        scene = context.scene
        folder = bpy.path.abspath(self.directory)
        try:
            os.makedirs(folder, exist_ok=True)
            keys = []
            settings = run.read_settings(scene, context.view_layer, keys)
            settings["exposure"] = scene.view_settings.exposure
            frames = range(scene.frame_start, scene.frame_end + 1) if self.animation else [scene.frame_current]
            shutter = settings["shutter"]
            if self.animation:
                # The whole range, with a frame either side for the shutter.
                kept = scene.frame_current
                scene.frame_set(scene.frame_start)
                run.export(scene, folder, (-1, scene.frame_end - scene.frame_start + 1))
                scene.frame_set(kept)
            else:
                run.export(scene, folder, shutter)
            os.makedirs(os.path.join(folder, "slurm"), exist_ok=True)
            for name in SLURM_FILES:
                shutil.copy(os.path.join(slurm_scripts(), name), os.path.join(folder, "slurm", name))
            submit = os.path.join(folder, "submit.sh")
            with open(submit, "w") as f:
                f.write(job_script(settings, self.tasks, frames))
            os.chmod(submit, 0o755)
        except (run.RenderFailed, OSError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        self.report({"INFO"}, f"gridtrace: wrote the Slurm job to {folder}")
        return {"FINISHED"}


def register():
    bpy.utils.register_class(GRIDTRACE_OT_write_farm_job)


def unregister():
    bpy.utils.unregister_class(GRIDTRACE_OT_write_farm_job)
