"""veil for Blender: a render engine for volumes (VDB smoke, fog) through veil, and an exporter of
veil scene files for veil render, veil turntable and Slurm farms. docs/blender.md."""

bl_info = {
    "name": "veil",
    "author": "the veil project",
    "version": (0, 3, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > veil; File > Export > veil Scene (.json)",
    "description": "Renders Volume objects (OpenVDB) with veil's participating-media renderer",
    "category": "Render",
}

if "bpy" in locals():  # Blender's "Reload Scripts": pick up edited modules
    import importlib
    for _m in (props, export, engine, ui):  # noqa: F821
        importlib.reload(_m)
else:
    from . import props, export, engine, ui  # noqa: F401

import bpy  # noqa: E402,F401  (after the reload test above, which looks for it)

_modules = (props, engine, ui)


def register():
    for m in _modules:
        m.register()


def unregister():
    for m in reversed(_modules):
        m.unregister()
