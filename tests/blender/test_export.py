"""File > Export > veil Scene as a hostile disk and scene meet it (issue 41, items 2 and 10), without
rendering:

- the scene JSON and its render script are written to temporary files and renamed over their targets:
  a full disk (RLIMIT_FSIZE: a write past half the scene fails with EFBIG, as ENOSPC would) leaves the
  previous export byte for byte and no temporary file; a target in a read-only file system (/proc), in
  a missing folder, or that is a folder is an ERROR in Blender's report (RuntimeError in a script),
  never a traceback;
- a packed VDB is an ERROR naming the volume and "packed" (before: exported with a path that does not
  exist); a light whose power or colour is NaN is an ERROR naming the light; a scene with no volume
  warns.

    blender -b --factory-startup --python tests/blender/test_export.py -- WORKDIR
"""
import json
import os
import resource
import signal
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402

from veil_blender import export  # noqa: E402  (common put it on sys.path)

work = common.args()[0]
os.makedirs(work, exist_ok=True)
vdb = os.path.join(work, "sphere.vdb")
common.write_sphere_vdb(vdb)
ob = common.build_scene(vdb)
target = os.path.join(work, "shot.json")


def export_to(path):
    """The operator's result and its ERROR message (Blender raises RuntimeError for an ERROR report)."""
    try:
        return bpy.ops.veil.export_scene(filepath=path), None
    except RuntimeError as e:
        return None, str(e)


def leftovers():
    return sorted(n for n in os.listdir(work) if "veil-tmp" in n)


r, e = export_to(target)
check(r == {'FINISHED'} and e is None, "export: %s %s" % (r, e))
good = open(target, "rb").read()
script = open(os.path.join(work, "shot.render.sh"), "rb").read()
check(json.loads(good)["medium"]["sources"][0]["file"] == vdb, "the export reads back")

# a full disk: every write past half the scene's bytes fails; the previous export stays whole
old = resource.getrlimit(resource.RLIMIT_FSIZE)
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
ob.location.x += 0.5  # a different scene: a write that went through would show
resource.setrlimit(resource.RLIMIT_FSIZE, (len(good) // 2, old[1]))
r, e = export_to(target)
resource.setrlimit(resource.RLIMIT_FSIZE, old)
check(e is not None and "shot.json" in e, "a full disk is an error naming the file: %s" % e)
check(open(target, "rb").read() == good and open(os.path.join(work, "shot.render.sh"), "rb").read() == script,
      "a full disk left the previous export and script as they were")
check(leftovers() == [], "no temporary file left: %s" % leftovers())

for what, path in (("a read-only file system", "/proc/veil_shot.json"),
                   ("a missing folder", os.path.join(work, "no", "such", "shot.json")),
                   ("a folder", os.path.join(work, "folder.json"))):
    if what == "a folder":
        os.makedirs(path, exist_ok=True)
    r, e = export_to(path)
    check(e is not None and os.path.basename(path) in e and "Traceback" not in e,
          "%s is an error naming the file: %s" % (what, e))
check(os.path.isdir(os.path.join(work, "folder.json")) and leftovers() == [], "nothing left: %s" % leftovers())

# a light whose power is NaN: an error naming it (before: a black light, silently)
light = next(o for o in bpy.context.scene.objects if o.type == 'LIGHT')
light.data.energy = float("nan")
r, e = export_to(target)
check(e is not None and light.name in e and "not a number" in e, "a NaN power is an error: %s" % e)
light.data.energy = 1000.0
check(open(target, "rb").read() == good, "a refused export left the file as it was")

# no volume: a warning (the image shows no medium)
ob.hide_render = True
data, warnings = export.export_scene(bpy.context.evaluated_depsgraph_get())
check(data["medium"]["sources"] == [] and any("no Volume object" in w for w in warnings),
      "no volume warns: %s" % warnings)
ob.hide_render = False

# a packed VDB: an error naming the volume (Blender reads it from the .blend; the path may hold anything)
bpy.ops.file.pack_all()
check(ob.data.packed_file is not None, "the volume is packed")
os.remove(vdb)  # the path no longer exists, as in a .blend moved to another machine
r, e = export_to(target)
check(e is not None and "packed" in e and ob.name in e, "a packed VDB is an error: %s" % e)
check(open(target, "rb").read() == good, "a refused export left the file as it was")
common.finish()
