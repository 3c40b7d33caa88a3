"""Headless OpenGL for MuJoCo's offscreen renderer: pick EGL or OSMesa, open a context.

MuJoCo picks its GL backend from ``MUJOCO_GL`` when ``mujoco`` is first imported, and most
processes here import it for simulation before they render. So rendering does not rely on
that choice: it creates the offscreen context itself with the backend :func:`gl_backend`
picks (``$MUJOCO_GL`` when it is ``egl`` or ``osmesa``, else the first of EGL, OSMesa that
works in a throw-away subprocess).
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys

from simdiff.errors import SimdiffError

GL_BACKENDS: tuple[str, ...] = ("egl", "osmesa")
"""Headless OpenGL backends tried, in order."""

_INSTALL_HINT = (
    "no headless OpenGL for MuJoCo rendering (tried {tried}); install EGL "
    "(`apt-get install libegl1 libegl-mesa0`) or OSMesa (`apt-get install libosmesa6`), "
    "or set MUJOCO_GL=egl|osmesa"
)

_PROBE = """
import importlib, sys
backend = sys.argv[1]
mod = importlib.import_module("mujoco." + backend)
import mujoco
ctx = mod.GLContext(16, 16)
ctx.make_current()
model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100.value)
con.free()
ctx.free()
print("ok")
"""


def _probe(backend: str, timeout: float = 120.0) -> bool:
    """True when ``backend`` creates a MuJoCo render context in a fresh Python process."""
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    try:
        proc = subprocess.run([sys.executable, "-c", _PROBE, backend], env=env, capture_output=True, text=True,
                              timeout=timeout)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return proc.returncode == 0 and proc.stdout.strip().endswith("ok")


@functools.lru_cache(maxsize=1)
def gl_backend() -> str:
    """The headless OpenGL backend to render with: ``"egl"`` or ``"osmesa"``.

    ``$MUJOCO_GL`` wins when it names one of them; otherwise, if PyOpenGL's platform is
    already fixed in this process (``$PYOPENGL_PLATFORM``), that one; otherwise the first of
    EGL, OSMesa whose library is installed and that opens a context in a subprocess (the
    probe costs about a second, once per process).

    Raises:
        SimdiffError: one line naming what to install when neither works.
    """
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    if chosen in GL_BACKENDS:
        return chosen
    fixed = os.environ.get("PYOPENGL_PLATFORM", "").strip().lower()
    candidates = (fixed,) if fixed in GL_BACKENDS else GL_BACKENDS
    if fixed and fixed not in GL_BACKENDS:
        raise SimdiffError(_INSTALL_HINT.format(tried=f"PYOPENGL_PLATFORM={fixed!r} is not headless"))
    import ctypes.util

    libs = {"egl": "EGL", "osmesa": "OSMesa"}
    found = [b for b in candidates if ctypes.util.find_library(libs[b])]
    for backend in found:
        if _probe(backend):
            return backend
    raise SimdiffError(_INSTALL_HINT.format(tried=", ".join(candidates)))


def _gl_context(backend: str, width: int, height: int):
    """An offscreen GL context of ``backend`` (made current), from MuJoCo's own wrappers."""
    import importlib

    try:
        module = importlib.import_module(f"mujoco.{backend}")
        ctx = module.GLContext(width, height)
        ctx.make_current()
    except Exception as exc:  # ImportError, RuntimeError, GLError: all mean "this backend does not work here"
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise SimdiffError(_INSTALL_HINT.format(tried=f"{backend}: {msg}")) from None
    return ctx
