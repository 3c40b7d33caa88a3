"""Opt-in: our BVH imported by Blender itself gives back the joints.

Set SIMDIFF_BLENDER_PYTHON to a Python interpreter that has ``bpy`` (Blender as a module)
to run it; skipped otherwise (CI has no Blender).
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from simdiff.motion import synthetic
from simdiff.motion.io import write_bvh

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(not os.environ.get("SIMDIFF_BLENDER_PYTHON"), reason="SIMDIFF_BLENDER_PYTHON not set")
def test_blender_imports_our_bvh(tmp_path: Path) -> None:
    joints = synthetic.walk(40, turn_rate=0.6)
    write_bvh(tmp_path / "walk.bvh", joints)
    np.save(tmp_path / "walk.npy", joints)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    out = subprocess.run(
        [os.environ["SIMDIFF_BLENDER_PYTHON"], str(Path(__file__).parent / "blender_bvh_check.py"),
         str(tmp_path / "walk.bvh"), str(tmp_path / "walk.npy")],
        capture_output=True, text=True, env=env, timeout=300, check=True,
    ).stdout
    mean_mm = float(re.search(r"mean ([0-9.]+) mm", out).group(1))
    assert mean_mm < 0.1
