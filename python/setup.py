"""Builds the `veil` package: the Python files plus a libveil.so to load.

Where the library comes from (build step, build_py):
  VEIL_LIBRARY=path/to/libveil.so   that library (a build's; no rebuild)
  otherwise                         CMake builds the repository's `veil_shared`
                                    target in python/build-lib/ (Release; jobs:
                                    CMAKE_BUILD_PARALLEL_LEVEL, else every core)
What the package holds (VEIL_PYTHON_LIBRARY):
  copy (default)  the library inside the package, veil/lib/libveil.so: the
                  installed package needs nothing else of the build
  record          veil/_libpath.py records the library's absolute path
                  (a developer's install that follows rebuilds)
  system          neither: the module asks the system loader (libveil.so
                  installed by `cmake --install` into a folder ld.so searches)
The package's version is include/veil.h's; at import, veil.__version__ is
the loaded library's.
"""

import os
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def header_version():
    header = os.path.join(REPO, "include", "veil.h")
    try:
        with open(header) as f:
            text = f.read()
    except OSError as e:
        sys.exit("setup.py: cannot read %s (%s): build the package from the veil repository's python/ folder"
                 % (header, e))
    parts = []
    for part in ("MAJOR", "MINOR", "PATCH"):
        m = re.search(r"^#define VEIL_VERSION_%s +([0-9]+)$" % part, text, re.M)
        if not m:
            sys.exit("setup.py: %s defines no VEIL_VERSION_%s" % (header, part))
        parts.append(m.group(1))
    return ".".join(parts)


def cmake_build():
    """libveil.so built from the repository with CMake in python/build-lib/."""
    cmake = shutil.which(os.environ.get("CMAKE", "cmake"))
    if not cmake:
        sys.exit("setup.py: no VEIL_LIBRARY given and no cmake to build libveil.so with: install cmake "
                 "(scripts/install-deps.sh installs what the build needs) or set VEIL_LIBRARY=path/to/libveil.so")
    build = os.path.join(HERE, "build-lib")
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 2)
    for cmd in ([cmake, "-S", REPO, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DBUILD_TESTING=OFF"],
                [cmake, "--build", build, "--target", "veil_shared", "-j", jobs]):
        print("setup.py: " + " ".join(cmd), flush=True)
        if subprocess.call(cmd) != 0:
            sys.exit("setup.py: `%s` failed; scripts/install-deps.sh installs what the build needs" % " ".join(cmd))
    path = os.path.join(build, "libveil.so")
    if not os.path.exists(path):
        sys.exit("setup.py: the CMake build made no %s" % path)
    return path


def library():
    env = os.environ.get("VEIL_LIBRARY")
    if env:
        path = os.path.join(env, "libveil.so") if os.path.isdir(env) else env
        if not os.path.isfile(path):
            sys.exit("setup.py: VEIL_LIBRARY=%s: no such file" % env)
        return os.path.realpath(path)
    return os.path.realpath(cmake_build())


class BuildPyWithLibrary(build_py):
    """build_py, then the library (or its path) into the built package."""

    def run(self):
        super().run()
        mode = os.environ.get("VEIL_PYTHON_LIBRARY", "copy")
        if mode not in ("copy", "record", "system"):
            sys.exit("setup.py: VEIL_PYTHON_LIBRARY=%s: expected copy, record or system" % mode)
        package = os.path.join(self.build_lib, "veil")
        libdir = os.path.join(package, "lib")
        if os.path.isdir(libdir):
            shutil.rmtree(libdir)  # no stale copy from an earlier build
        libpath = os.path.join(package, "_libpath.py")
        if os.path.exists(libpath):
            os.remove(libpath)
        if mode == "system":
            return
        lib = library()
        if mode == "record":
            with open(libpath, "w") as f:
                f.write("# written by setup.py (VEIL_PYTHON_LIBRARY=record): the libveil.so this package loads\n"
                        "LIBRARY = %r\n" % lib)
            return
        os.makedirs(libdir)
        # the real file (not the symlink chain), under the plain name the module looks for
        shutil.copyfile(lib, os.path.join(libdir, "libveil.so"))
        shutil.copymode(lib, os.path.join(libdir, "libveil.so"))


cmdclass = {"build_py": BuildPyWithLibrary}
try:  # a library inside: a platform wheel, though for any Python 3 (ctypes, no extension module)
    from wheel.bdist_wheel import bdist_wheel

    class PlatformWheel(bdist_wheel):
        def finalize_options(self):
            super().finalize_options()
            self.root_is_pure = os.environ.get("VEIL_PYTHON_LIBRARY", "copy") == "system"

        def get_tag(self):
            python, abi, plat = super().get_tag()
            return ("py3", "none", plat) if not self.root_is_pure else (python, abi, plat)

    cmdclass["bdist_wheel"] = PlatformWheel
except ImportError:
    pass

setup(
    version=header_version(),
    packages=["veil"],
    cmdclass=cmdclass,
    zip_safe=False,
)
