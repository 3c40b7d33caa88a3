"""Small synthetic CMU-style mocap files (ASF/AMC, BVH, DeepMimic JSON) of a walking figure, for corpus tests."""

from __future__ import annotations

import json

import numpy as np


# name, parent, direction (x left, y up, z forward), length in ASF units (0.45 in)
_BONES = [
    ("lhipjoint", "root", (0.66, -0.71, 0.25), 2.5), ("lfemur", "lhipjoint", (0.34, -0.94, 0), 7.6),
    ("ltibia", "lfemur", (0.34, -0.94, 0), 7.6), ("lfoot", "ltibia", (0.09, -0.24, 0.97), 2.2),
    ("ltoes", "lfoot", (0, 0, 1), 1.1),
    ("rhipjoint", "root", (-0.66, -0.71, 0.25), 2.5), ("rfemur", "rhipjoint", (-0.34, -0.94, 0), 7.6),
    ("rtibia", "rfemur", (-0.34, -0.94, 0), 7.6), ("rfoot", "rtibia", (-0.09, -0.24, 0.97), 2.2),
    ("rtoes", "rfoot", (0, 0, 1), 1.1),
    ("lowerback", "root", (0, 1, -0.07), 2.0), ("upperback", "lowerback", (0, 1, 0.01), 2.0),
    ("thorax", "upperback", (0, 1, 0.02), 2.0), ("lowerneck", "thorax", (0, 1, 0.04), 1.5),
    ("upperneck", "lowerneck", (0, 1, -0.02), 1.5), ("head", "upperneck", (0, 1, 0.01), 1.5),
    ("lclavicle", "thorax", (0.9, 0.4, -0.1), 3.5), ("lhumerus", "lclavicle", (1, 0, 0), 5.0),
    ("lradius", "lhumerus", (1, 0, 0), 3.3), ("lwrist", "lradius", (1, 0, 0), 1.7),
    ("lhand", "lwrist", (1, 0, 0), 0.7), ("lfingers", "lhand", (1, 0, 0), 0.6),
    ("lthumb", "lwrist", (0.7, 0, 0.7), 0.8),
    ("rclavicle", "thorax", (-0.9, 0.4, -0.1), 3.5), ("rhumerus", "rclavicle", (-1, 0, 0), 5.0),
    ("rradius", "rhumerus", (-1, 0, 0), 3.3), ("rwrist", "rradius", (-1, 0, 0), 1.7),
    ("rhand", "rwrist", (-1, 0, 0), 0.7), ("rfingers", "rhand", (-1, 0, 0), 0.6),
    ("rthumb", "rwrist", (-0.7, 0, 0.7), 0.8),
]


def asf_text() -> str:
    lines = [":version 1.10", ":name SYN", ":units", "  mass 1.0", "  length 0.45", "  angle deg",
             ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ", "   position 0 0 0", "   orientation 0 0 0",
             ":bonedata"]
    for i, (name, _, direction, length) in enumerate(_BONES, start=1):
        lines += ["  begin", f"     id {i}", f"     name {name}", "     direction " + " ".join(map(str, direction)),
                  f"     length {length}", "     axis 0 0 0 XYZ", "    dof rx ry rz", "  end"]
    lines += [":hierarchy", "  begin"]
    children: dict[str, list[str]] = {}
    for name, parent, _, _ in _BONES:
        children.setdefault(parent, []).append(name)
    lines += [f"    {parent} {' '.join(kids)}" for parent, kids in children.items()]
    lines += ["  end"]
    return "\n".join(lines) + "\n"


def amc_text(seconds: float, fps: int, turn: float = 0.0) -> str:
    """A walk: root forward at 1.2 m/s (yawing ``turn`` rad/s), thighs and arms swinging."""
    unit = 0.0254 / 0.45
    lines = [":FULLY-SPECIFIED", ":DEGREES"]
    for k in range(int(seconds * fps)):
        t = k / fps
        swing = 25 * np.sin(2 * np.pi * t)
        yaw = turn * t
        x, z = (0.0, 1.2 * t) if turn == 0 else (1.2 / turn * (1 - np.cos(yaw)), 1.2 / turn * np.sin(yaw))
        lines.append(str(k + 1))
        lines.append(f"root {x / unit:.4f} {0.93 / unit:.4f} {z / unit:.4f} 0 {np.degrees(yaw):.4f} 0")
        for name, *_ in _BONES:
            rx = {"lfemur": -swing, "rfemur": swing, "ltibia": max(0.0, swing), "rtibia": max(0.0, -swing)}.get(name, 0.0)
            rz = {"lhumerus": -70.0, "rhumerus": 70.0}.get(name, 0.0)
            lines.append(f"{name} {rx:.4f} 0 {rz:.4f}")
    return "\n".join(lines) + "\n"


_BVH_JOINTS = [  # name, parent, offset in cm
    ("Hips", None, (0, 95, 0)), ("LeftUpLeg", "Hips", (9, -5, 0)), ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
    ("LeftFoot", "LeftLeg", (0, -41, 0)), ("LeftToeBase", "LeftFoot", (0, -5, 12)),
    ("RightUpLeg", "Hips", (-9, -5, 0)), ("RightLeg", "RightUpLeg", (0, -42, 0)),
    ("RightFoot", "RightLeg", (0, -41, 0)), ("RightToeBase", "RightFoot", (0, -5, 12)),
    ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 12, 0)), ("Spine2", "Spine1", (0, 12, 0)),
    ("Neck", "Spine2", (0, 16, 0)), ("Head", "Neck", (0, 10, 0)),
    ("LeftShoulder", "Spine2", (4, 12, 0)), ("LeftArm", "LeftShoulder", (14, 0, 0)),
    ("LeftForeArm", "LeftArm", (26, 0, 0)), ("LeftHand", "LeftForeArm", (25, 0, 0)),
    ("RightShoulder", "Spine2", (-4, 12, 0)), ("RightArm", "RightShoulder", (-14, 0, 0)),
    ("RightForeArm", "RightArm", (-26, 0, 0)), ("RightHand", "RightForeArm", (-25, 0, 0)),
]


def cmu_bvh_text(seconds: float, fps: int) -> str:
    """Biped BVH in cm: a T-pose frame, then a walk forward with swinging legs."""
    names = [j[0] for j in _BVH_JOINTS]
    lines = ["HIERARCHY"]

    def emit(index: int, depth: int) -> None:
        name, parent, offset = _BVH_JOINTS[index]
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(pad + "{")
        lines.append(f"{pad}  OFFSET {offset[0]} {offset[1]} {offset[2]}")
        channels = "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" if parent is None else "3 Zrotation Xrotation Yrotation"
        lines.append(f"{pad}  CHANNELS {channels}")
        kids = [i for i, j in enumerate(_BVH_JOINTS) if j[1] == name]
        for kid in kids:
            emit(kid, depth + 1)
        if not kids:
            lines.extend([f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET 0 0 5", pad + "  }"])
        lines.append(pad + "}")

    emit(0, 0)
    frames = int(seconds * fps)
    lines += ["MOTION", f"Frames: {frames + 1}", f"Frame Time: {1 / fps:.6f}"]
    lines.append(" ".join(["0", "95", "0"] + ["0"] * (3 * len(names))))  # the added T-pose
    for k in range(frames):
        t = k / fps
        swing = 25 * np.sin(2 * np.pi * t)
        values = [0.0, 95.0, 120.0 * t + 30.0]  # root jumps 30 cm after the T-pose
        for name in names:
            rot = {"LeftUpLeg": swing, "RightUpLeg": -swing, "LeftArm": -70.0, "RightArm": 70.0}.get(name, 0.0)
            values += [rot if name.endswith("Arm") else 0.0, 0.0 if name.endswith("Arm") else rot, 0.0]
        lines.append(" ".join(f"{v:.4f}" for v in values))
    return "\n".join(lines) + "\n"


def deepmimic_text(seconds: float, fps: int) -> str:
    frames = []
    for k in range(int(seconds * fps)):
        t = k / fps
        row = [1.0 / fps, 1.0 * t, 0.85, 0.0, 1.0, 0.0, 0.0, 0.0]  # walks along +X (its forward)
        half = 0.2 * np.sin(2 * np.pi * t)
        hip = [float(np.cos(half)), 0.0, 0.0, float(np.sin(half))]
        hip_l = [float(np.cos(-half)), 0.0, 0.0, float(np.sin(-half))]
        ident = [1.0, 0.0, 0.0, 0.0]
        # chest, neck, r hip, r knee, r ankle, r shoulder, r elbow, l hip, l knee, l ankle, l shoulder, l elbow
        row += ident + ident + hip + [0.0] + ident + ident + [0.0] + hip_l + [0.0] + ident + ident + [0.0]
        frames.append(row)
    return json.dumps({"Loop": "none", "Frames": frames})
