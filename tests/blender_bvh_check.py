"""Check a BVH written by simdiff against Blender's own BVH importer.

Run with a Python that has Blender's ``bpy`` module (``pip install bpy`` in its own
environment; it needs the Python version bpy was built for) and simdiff on PYTHONPATH::

    python tests/blender_bvh_check.py motion.bvh reference_joints.npy

Imports the BVH with the importer's defaults (scale 1, forward -Z, up Y), reads every pose
bone's head in world space each frame, maps Blender's Z-up back to Y-up, and prints the
mean and max distance in mm to the reference joints (T, 22, 3).
"""

from __future__ import annotations

import sys

import numpy as np


def main(bvh: str, reference: str) -> float:
    import bpy

    from simdiff.motion.skeleton import JOINT_NAMES

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_anim.bvh(filepath=bvh)
    armature = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    ref = np.load(reference)
    errors = []
    for t in range(ref.shape[0]):
        bpy.context.scene.frame_set(t + 1)
        heads = np.array([list(armature.matrix_world @ armature.pose.bones[n].head) for n in JOINT_NAMES])
        y_up = np.stack([heads[:, 0], heads[:, 2], -heads[:, 1]], axis=-1)
        errors.append(np.linalg.norm(y_up - ref[t], axis=-1))
    err = np.array(errors)
    print(f"{bvh}: {ref.shape[0]} frames, Blender import vs reference: mean {err.mean() * 1e3:.3f} mm, max {err.max() * 1e3:.3f} mm")
    return float(err.mean())


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
