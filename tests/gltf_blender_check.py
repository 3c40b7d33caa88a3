"""Check a glb written by simdiff against Blender's own glTF importer.

Run with a Python that has Blender's ``bpy`` module (``pip install bpy`` in its own environment; it needs the
Python version bpy was built for) and simdiff on PYTHONPATH::

    python tests/gltf_blender_check.py motion.glb reference_joints.npy FPS [reference_vertices.npy]

Sets the scene to FPS frames per second, imports the glb with the importer's defaults (+Y up converted to
Blender's +Z up), reads every pose bone's head in world space at each key frame, maps Blender's Z-up back to
Y-up, and prints the number of skinned vertices and the mean and max distance in mm to the reference joints
(T, 22, 3). With reference vertices (3, V, 3) (the skinned body at frames 0, T // 2 and T - 1), it also prints
the largest distance in mm of Blender's deformed body from them.
"""

from __future__ import annotations

import sys

import numpy as np


def main(glb: str, reference: str, fps: int, vertices: str | None = None) -> float:
    import bpy

    from simdiff.motion.skeleton import JOINT_NAMES

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.fps = fps
    bpy.context.scene.render.fps_base = 1.0
    bpy.ops.import_scene.gltf(filepath=glb)
    armature = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    meshes = [o for o in bpy.context.scene.objects if o.type == "MESH" and o.vertex_groups]
    count = sum(len(o.data.vertices) for o in meshes)
    skinned = bool(meshes) and all(any(m.type == "ARMATURE" and m.object == armature for m in o.modifiers)
                                   for o in meshes)
    start = int(round(armature.animation_data.action.frame_range[0]))
    ref = np.load(reference)
    errors = []
    for t in range(ref.shape[0]):
        bpy.context.scene.frame_set(start + t)
        heads = np.array([list(armature.matrix_world @ armature.pose.bones[n].head) for n in JOINT_NAMES])
        y_up = np.stack([heads[:, 0], heads[:, 2], -heads[:, 1]], axis=-1)
        errors.append(np.linalg.norm(y_up - ref[t], axis=-1))
    err = np.array(errors)
    if vertices is not None and meshes:
        want = np.load(vertices)
        worst = 0.0
        for t, ref_v in zip((0, ref.shape[0] // 2, ref.shape[0] - 1), want):
            bpy.context.scene.frame_set(start + t)
            depsgraph = bpy.context.evaluated_depsgraph_get()
            body = meshes[0].evaluated_get(depsgraph)
            data = body.to_mesh()
            co = np.array([list(body.matrix_world @ v.co) for v in data.vertices])
            body.to_mesh_clear()
            co = np.stack([co[:, 0], co[:, 2], -co[:, 1]], axis=-1)
            worst = max(worst, float(np.linalg.norm(co - ref_v, axis=-1).max()) if co.shape == ref_v.shape
                        else float("inf"))
        print(f"deformed body vs reference skinning: max {worst * 1e3:.3f} mm")
    print(f"{glb}: {ref.shape[0]} frames, {len(meshes)} skinned mesh(es), {count} vertices, armature modifier {skinned}, "
          f"Blender import vs reference: mean {err.mean() * 1e3:.3f} mm, max {err.max() * 1e3:.3f} mm")
    return float(err.mean())


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 20,
         sys.argv[4] if len(sys.argv) > 4 else None)
