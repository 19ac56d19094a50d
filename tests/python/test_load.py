# SPDX-License-Identifier: Apache-2.0
"""Finding the library: the build's copy names the library built beside
it; VDBPACK_LIBRARY overrides; a library that cannot be found or is of
another version gives one clear ImportError line."""
import os
import re
import shutil
import subprocess
import sys

import vdbpack
from conftest import run_cli

PKG = os.path.dirname(vdbpack.__file__)


def run_python(code, env_extra=None, pythonpath=None, drop_library_env=True):
    env = dict(os.environ)
    if drop_library_env:
        env.pop("VDBPACK_LIBRARY", None)
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    env.update(env_extra or {})
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=60)


def import_error_line(r):
    """The last line of the traceback: 'ImportError: ...', and no chained
    traceback (no 'During handling ...') before it."""
    assert r.returncode == 1, (r.returncode, r.stderr)
    lines = r.stderr.rstrip().splitlines()
    assert lines[-1].startswith("ImportError: vdbpack: "), r.stderr
    assert "During handling" not in r.stderr and "OSError" not in r.stderr, r.stderr
    assert sum(1 for x in lines if re.match(r"[A-Za-z.]*Error: ", x)) == 1, r.stderr
    return lines[-1]


def test_version_is_the_librarys_and_the_clis():
    assert vdbpack.version() == vdbpack.__version__
    out = run_cli("--version").stdout.splitlines()[0]
    assert out == "vdbpack " + vdbpack.version()
    from vdbpack import _lib
    assert _lib.lib.vp_version().decode() == vdbpack.version()


def test_the_build_copy_loads_the_build_library():
    path = vdbpack.library_path()
    assert os.path.isabs(path) and os.path.exists(path)
    from vdbpack import _libpath
    assert _libpath.RELATIVE is False and path == _libpath.LIBRARY
    assert _libpath.VERSION == vdbpack.version()


def test_vdbpack_library_overrides():
    lib = os.path.realpath(vdbpack.library_path())
    r = run_python("import vdbpack; print(vdbpack.library_path())",
                   {"VDBPACK_LIBRARY": lib}, drop_library_env=False)
    assert r.returncode == 0 and r.stdout.strip() == lib, r.stderr


def test_a_missing_library_named_by_the_environment(tmp_path):
    r = run_python("import vdbpack", {"VDBPACK_LIBRARY": "/nonexistent/libvdbpack.so"},
                   drop_library_env=False)
    line = import_error_line(r)
    assert "VDBPACK_LIBRARY=/nonexistent/libvdbpack.so" in line
    assert "No such file" in line


def test_a_copy_without_its_library(tmp_path):
    """The package copied elsewhere without _libpath.py, no VDBPACK_LIBRARY,
    and no libvdbpack that ctypes.util.find_library can see: one line that
    says what was tried and how to fix it."""
    dst = tmp_path / "site" / "vdbpack"
    shutil.copytree(PKG, dst, ignore=shutil.ignore_patterns("_libpath.py", "__pycache__"))
    r = run_python("import vdbpack", pythonpath=str(tmp_path / "site"),
                   env_extra={"LD_LIBRARY_PATH": ""})
    line = import_error_line(r)
    assert "_libpath.py: absent" in line and "find_library('vdbpack')" in line
    assert "Set VDBPACK_LIBRARY to the path of libvdbpack.so" in line
    # and with VDBPACK_LIBRARY it works
    r = run_python("import vdbpack; print(vdbpack.pack('box:1,1,1', radius=0.2).__len__())",
                   pythonpath=str(tmp_path / "site"),
                   env_extra={"VDBPACK_LIBRARY": vdbpack.library_path()})
    assert r.returncode == 0 and r.stdout.strip() == "14", r.stderr


def test_a_library_of_another_version(tmp_path):
    dst = tmp_path / "site" / "vdbpack"
    shutil.copytree(PKG, dst, ignore=shutil.ignore_patterns("__pycache__"))
    text = (dst / "_libpath.py").read_text()
    (dst / "_libpath.py").write_text(text.replace('VERSION = "%s"' % vdbpack.version(),
                                                  'VERSION = "0.0.1"'))
    r = run_python("import vdbpack", pythonpath=str(tmp_path / "site"))
    line = import_error_line(r)
    assert "version 0.0.1" in line and "version %s" % vdbpack.version() in line


def test_a_library_that_is_not_vdbpack(tmp_path):
    import ctypes.util
    libm = ctypes.util.find_library("m")
    r = run_python("import vdbpack", {"VDBPACK_LIBRARY": libm}, drop_library_env=False)
    line = import_error_line(r)
    assert "has no function vp_" in line
