"""A Volume whose VDB file is missing: F12 (bpy.ops.render.render) with the veil engine reports the
file in Blender's report (an ERROR naming the object and the path), ends the render cleanly (no
traceback, no crash, no image written) and Blender goes on: a second render after the file is
restored succeeds in the same process. The driver (run.sh) also checks Blender's log for the
message and for the absence of a Python traceback.

    blender -b --factory-startup --python tests/blender/test_missing.py -- WORKDIR
"""
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402

work = common.args()[0]
os.makedirs(work, exist_ok=True)
missing = os.path.join(work, "missing_smoke.vdb")
if os.path.exists(missing):
    os.remove(missing)
ob = common.build_scene(missing, volume_name="MissingSmoke")
sc = bpy.context.scene
out = os.path.join(work, "missing.exr")
if os.path.exists(out):
    os.remove(out)
sc.render.filepath = out
sc.render.image_settings.file_format = 'OPEN_EXR'
raised = None
try:
    r = bpy.ops.render.render(write_still=True)
except RuntimeError as e:  # Blender turns an operator's ERROR report into RuntimeError in scripts
    raised = str(e)
print("render operator:", raised or r, flush=True)
check(not os.path.exists(out), "no image written for a failed render (%s)" % out)
if raised is not None:
    check("cannot read" in raised and missing in raised, "the operator's error names the file: %s" % raised)

# the same process renders once the file exists: the failure left nothing behind
common.write_sphere_vdb(missing)
ob.data.filepath = missing  # a new path value makes Blender reload the grids
r = bpy.ops.render.render(write_still=True)
check(os.path.exists(out), "after the file is written, the next render in the same Blender succeeds (%s)" % r)
common.finish()
