"""A scene argument (a dict, JSON text or a path) turned into what veil reads.

veil itself parses and checks the scene (docs/scene-format.md): the module
only serialises a dict, applies the `quality` override, and says where the
text came from so that veil's messages name the file.
"""

import json
import math
import os

import numpy as np

from ._errors import VeilError
from ._lib import RESULT_CODES

QUALITIES = ("draft", "default", "high", "max")


class SceneText:
    """What veil gets: either a file to open as it is (path set, text None)
    or JSON text with the folder its relative paths resolve against and the
    name its messages start with."""

    def __init__(self, text=None, base_dir=None, name=None, path=None, data=None, unparsed=None, file=None):
        self.text = text
        self.file = path if file is None else file  # the scene's file, when it came from one
        self.unparsed = unparsed  # why Python's json could not read text that an override needed
        self.base_dir = base_dir
        self.name = name
        self.path = path
        self.data = data  # the parsed scene where the module has it (a dict), else None


def _json_default(value):
    """numpy values inside a scene dict (a transform as an ndarray, a numpy float)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError("scene: a %s is not a JSON value" % type(value).__name__)


def _non_finite_path(value, path=""):
    """The JSON path ("camera.position[1]") of the first number that is not finite, or None."""
    if isinstance(value, float) or isinstance(value, np.floating):
        return None if math.isfinite(value) else path
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and not np.all(np.isfinite(value)):
            flat = int(np.flatnonzero(~np.isfinite(value.ravel()))[0])
            index = np.unravel_index(flat, value.shape)
            return path + "".join("[%d]" % i for i in index)
        return None
    if isinstance(value, dict):
        for k, v in value.items():
            found = _non_finite_path(v, "%s.%s" % (path, k) if path else str(k))
            if found:
                return found
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            found = _non_finite_path(v, "%s[%d]" % (path, i))
            if found:
                return found
    return None


def _dumps(scene, name):
    bad = _non_finite_path(scene)
    if bad is not None:
        raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"],
                        "%s: %s: expected a finite number, got a value that is not (not a number or "
                        "infinite); the scene format takes finite numbers only" % (name, bad))
    return json.dumps(scene, default=_json_default, allow_nan=False)


def _strict_loads(text):
    """json.loads that refuses what veil refuses and Python's json would let through:
    repeated keys (which json.loads would silently merge) and NaN/Infinity."""

    def pairs(items):
        seen = {}
        for k, v in items:
            if k in seen:
                raise ValueError("key '%s' given twice" % k)
            seen[k] = v
        return seen

    def constant(token):
        raise ValueError("%s is not a JSON number" % token)

    return json.loads(text, object_pairs_hook=pairs, parse_constant=constant)


def _is_path(scene):
    if isinstance(scene, os.PathLike):
        return True
    return isinstance(scene, str) and not scene.lstrip().startswith("{")


def prepare(scene, quality=None, base_dir=None):
    """SceneText for a dict, JSON text (str or bytes) or a path (str or os.PathLike)."""
    if quality is not None and quality not in QUALITIES:
        raise ValueError("quality: expected one of %s, got %r" % (", ".join(map(repr, QUALITIES)), quality))
    if base_dir is not None:
        base_dir = os.fspath(base_dir)

    if isinstance(scene, dict):
        name = "<scene dict>"
        if quality is not None:
            scene = dict(scene, quality=quality)
        return SceneText(_dumps(scene, name), base_dir, name, data=scene)

    if isinstance(scene, (bytes, bytearray)):
        scene = bytes(scene).decode("utf-8")
    if _is_path(scene):
        path = os.fspath(scene)
        if isinstance(path, bytes):
            path = os.fsdecode(path)
        if quality is None and base_dir is None:
            return SceneText(path=path)  # veil reads the file itself (and says if it cannot)
        try:
            with open(path, "rb") as f:
                text = f.read().decode("utf-8")
        except (OSError, UnicodeDecodeError):
            return SceneText(path=path)  # veil's own message: cannot open, not UTF-8
        folder = base_dir if base_dir is not None else os.path.dirname(os.path.abspath(path))
        st = _text_scene(text, folder, path, quality)
        st.file = path
        return st

    if not isinstance(scene, str):
        raise TypeError("scene: expected a dict, JSON text or a path to a .json file, got %s"
                        % type(scene).__name__)
    return _text_scene(scene, base_dir, "<scene json>", quality)


def _text_scene(text, base_dir, name, quality):
    try:
        data = _strict_loads(text)
    except ValueError as e:
        # veil parses the text as it is and says where it is malformed; should veil accept what
        # Python's json refused, the override cannot be applied and that is an error (render())
        return SceneText(text, base_dir, name, unparsed=str(e) if quality is not None else None)
    if not isinstance(data, dict):
        return SceneText(text, base_dir, name)  # veil: "the top-level value must be an object"
    if quality is not None:
        data["quality"] = quality
        text = _dumps(data, name)
    return SceneText(text, base_dir, name, data=data)


def grid_names(data):
    """The grid names a scene's "array" sources read (their "grid", emission and temperature grids)."""
    names = set()
    try:
        sources = data["medium"]["sources"]
    except (KeyError, TypeError):
        return names
    for s in sources if isinstance(sources, list) else []:
        if not isinstance(s, dict) or s.get("type") != "array":
            continue
        names.add(s.get("grid"))
        for key in ("emission", "temperature"):
            sub = s.get(key)
            if isinstance(sub, dict) and "grid" in sub:
                names.add(sub["grid"])
    return names
