"""Packaging: `pip install --no-index --no-build-isolation` of python/ into a venv made with
--system-site-packages (no network), the library taken from VEIL_LIBRARY (the build's: no rebuild)
and copied into the package; the installed module then imports and renders on its own."""

import json
import os
import shutil
import subprocess
import textwrap

import numpy as np

import veil
from conftest import REPO, scene


def test_pip_install_into_a_venv(gl, tmp_path):
    # the package's sources as a fresh clone lays them out (setup.py reads ../include/veil.h),
    # copied so that pip's in-tree build leaves nothing in the working tree
    src = tmp_path / "src"
    shutil.copytree(os.path.join(REPO, "python"), src / "python",
                    ignore=shutil.ignore_patterns("build", "build-lib", "*.egg-info", "__pycache__", "lib",
                                                  "_libpath.py"))
    (src / "include").mkdir()
    shutil.copy(os.path.join(REPO, "include", "veil.h"), src / "include" / "veil.h")
    venv = tmp_path / "venv"
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", str(venv)], check=True)
    py = str(venv / "bin" / "python")
    env = dict(os.environ, VEIL_LIBRARY=veil.library_path(), PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)
    pip = subprocess.run([py, "-m", "pip", "install", "--no-index", "--no-build-isolation", "."],
                         cwd=src / "python", env=env, capture_output=True, text=True)
    assert pip.returncode == 0, pip.stdout + pip.stderr

    # the installed module, on its own: no VEIL_LIBRARY, no PYTHONPATH, not run from the sources
    s = scene({"type": "rbf", "particles": [{"center": [0, 0, 0], "amplitude": 2.0, "sharpness": 2.0}]})
    script = textwrap.dedent("""
        import json, sys, numpy as np, veil
        out = veil.render(json.loads(sys.argv[1]))
        np.save(sys.argv[2], out["rgba"])
        print(veil.__version__)
        print(veil.library_path())
        print(veil.__file__)
        """)
    env.pop("VEIL_LIBRARY")
    run = subprocess.run([py, "-c", script, json.dumps(s), str(tmp_path / "rgba.npy")],
                         cwd=tmp_path, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    version, library, module = run.stdout.split("\n")[:3]
    assert version == veil.__version__
    assert module.startswith(str(venv)) and library.startswith(str(venv)), (module, library)
    # the copy inside the package renders what the build's library renders, bit for bit
    np.testing.assert_array_equal(np.load(tmp_path / "rgba.npy"), veil.render(s)["rgba"])
