"""The module itself: its version against include/veil.h, finding the library, the scene argument
and the error type, all without a GL context."""

import os
import re
import subprocess
import sys

import pytest

import veil
from conftest import REPO


def header_version():
    with open(os.path.join(REPO, "include", "veil.h")) as f:
        text = f.read()
    return tuple(int(re.search(r"^#define VEIL_VERSION_%s +([0-9]+)$" % p, text, re.M).group(1))
                 for p in ("MAJOR", "MINOR", "PATCH"))


def test_version_is_the_headers_and_the_librarys():
    major, minor, patch = header_version()
    assert veil.__version__ == "%d.%d.%d" % (major, minor, patch)
    assert veil.version_info == (major, minor, patch)
    cli = subprocess.run([os.environ["VEIL_CLI"], "--version"], capture_output=True, text=True)
    assert cli.stdout.strip() == "veil " + veil.__version__


def run_import(env_changes, code="import veil; print(veil.library_path())"):
    env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"))
    env.update(env_changes)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd="/")


def test_library_from_veil_library():
    lib = os.path.realpath(veil.library_path())
    r = run_import({"VEIL_LIBRARY": lib})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == lib
    r = run_import({"VEIL_LIBRARY": os.path.dirname(veil.library_path())})  # a folder holding libveil.so
    assert r.returncode == 0 and r.stdout.strip() == os.path.join(os.path.dirname(veil.library_path()),
                                                                  "libveil.so"), r.stderr


def test_missing_library_says_what_was_tried(tmp_path):
    r = run_import({"VEIL_LIBRARY": str(tmp_path / "nowhere" / "libveil.so")})
    assert r.returncode != 0
    assert "ImportError" in r.stderr and "VEIL_LIBRARY" in r.stderr and "nowhere/libveil.so" in r.stderr
    notveil = tmp_path / "libnotveil.so"
    notveil.write_bytes(open("/usr/lib/x86_64-linux-gnu/libm.so.6", "rb").read()
                        if os.path.exists("/usr/lib/x86_64-linux-gnu/libm.so.6") else b"")
    r = run_import({"VEIL_LIBRARY": str(notveil)})
    assert r.returncode != 0 and "libnotveil.so" in r.stderr


def test_error_type():
    e = veil.VeilError(2, "scene.json: camera.fov_y_deg: expected a number")
    assert (e.code, e.name) == (2, "VEIL_ERR_PARSE") and str(e) == "VEIL_ERR_PARSE: " + e.message
    assert issubclass(veil.Cancelled, veil.VeilError)
    assert veil.RESULT_CODES["VEIL_ERR_CANCELLED"] == 8


def test_scene_argument_types(tmp_path):
    with pytest.raises(TypeError, match="scene"):
        veil.render(42)
    with pytest.raises(veil.VeilError) as e:
        veil.render('{"camera": ')  # JSON text: veil's parser reports it
    assert e.value.name == "VEIL_ERR_PARSE" and "<scene json>" in e.value.message
    with pytest.raises(veil.VeilError) as e:
        veil.render('{"camera": {}, "camera": {}}', quality="draft")  # a repeated key is refused, not merged
    assert e.value.name in ("VEIL_ERR_PARSE", "VEIL_ERR_INVALID") and "camera" in e.value.message
