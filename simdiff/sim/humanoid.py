"""An SMPL-layout MuJoCo humanoid generated from the HumanML3D skeleton.

The model is written by :func:`build_mjcf` from :mod:`simdiff.motion.skeleton` (bone lengths),
never copied from a third-party file.

Layout (24 bodies, SMPL order): Pelvis (free joint), L_Hip (thigh), L_Knee (shank), L_Ankle
(foot), L_Toe, R_Hip, R_Knee, R_Ankle, R_Toe, Torso, Spine, Chest, Neck, Head, L_Thorax
(collar), L_Shoulder (upper arm), L_Elbow (forearm), L_Wrist, L_Hand, and the right arm.
Each non-root body has three hinges about its own x, y, z axes (applied in that order,
i.e. intrinsic XYZ Euler angles), 69 hinges in all; nq = 76, nv = 75, nu = 69.

Frames: MuJoCo world is Z-up. A HumanML3D point (x, y, z) (Y-up, facing +Z, left +X) maps to
world (z, x, y): the character faces +x, its left is +y. At rest (all hinges 0) every body
frame is world-aligned: arms stretched sideways (T-pose), legs straight, feet flat.

Actuators are symmetric PD position servos (``general``, affine bias): the control is the
target angle in radians, ``τ = kp (u − q) − kd q̇``, clipped to ±forcerange. There is no
actuator on the root. Self-collisions are disabled (body geoms collide with the floor only),
a deliberate simplification for tracking retargeted references.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from simdiff.motion.skeleton import BONE_LENGTHS

BODY_NAMES: tuple[str, ...] = (
    "Pelvis", "L_Hip", "L_Knee", "L_Ankle", "L_Toe", "R_Hip", "R_Knee", "R_Ankle", "R_Toe",
    "Torso", "Spine", "Chest", "Neck", "Head", "L_Thorax", "L_Shoulder", "L_Elbow", "L_Wrist",
    "L_Hand", "R_Thorax", "R_Shoulder", "R_Elbow", "R_Wrist", "R_Hand",
)
"""The 24 bodies in SMPL order (model body id = index + 1; id 0 is the world)."""

BODY_PARENT: dict[str, str | None] = {
    "Pelvis": None, "L_Hip": "Pelvis", "L_Knee": "L_Hip", "L_Ankle": "L_Knee", "L_Toe": "L_Ankle",
    "R_Hip": "Pelvis", "R_Knee": "R_Hip", "R_Ankle": "R_Knee", "R_Toe": "R_Ankle",
    "Torso": "Pelvis", "Spine": "Torso", "Chest": "Spine", "Neck": "Chest", "Head": "Neck",
    "L_Thorax": "Chest", "L_Shoulder": "L_Thorax", "L_Elbow": "L_Shoulder", "L_Wrist": "L_Elbow",
    "L_Hand": "L_Wrist", "R_Thorax": "Chest", "R_Shoulder": "R_Thorax", "R_Elbow": "R_Shoulder",
    "R_Wrist": "R_Elbow", "R_Hand": "R_Wrist",
}

BODY_TO_HML: dict[str, int] = {
    "Pelvis": 0, "L_Hip": 1, "R_Hip": 2, "Torso": 3, "L_Knee": 4, "R_Knee": 5, "Spine": 6,
    "L_Ankle": 7, "R_Ankle": 8, "Chest": 9, "L_Toe": 10, "R_Toe": 11, "Neck": 12,
    "L_Thorax": 13, "R_Thorax": 14, "Head": 15, "L_Shoulder": 16, "R_Shoulder": 17,
    "L_Elbow": 18, "R_Elbow": 19, "L_Wrist": 20, "R_Wrist": 21,
}
"""Body → HumanML3D joint index; the body origin *is* that joint. Hands have no joint."""

HML_BODY_IDS: np.ndarray = np.array(
    [BODY_NAMES.index(next(b for b, j in BODY_TO_HML.items() if j == i)) + 1 for i in range(22)]
)
"""(22,) model body id of each HumanML3D joint, in HumanML3D order."""

FOOT_BODIES: tuple[str, ...] = ("L_Ankle", "L_Toe", "R_Ankle", "R_Toe")
HAND_BODIES: tuple[str, ...] = ("L_Wrist", "L_Hand", "R_Wrist", "R_Hand")

HML_TO_WORLD: np.ndarray = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
"""World = HML_TO_WORLD @ hml: HumanML3D (x, y, z) Y-up → MuJoCo (z, x, y) Z-up (det +1)."""


TOE_JOINT_HEIGHT: float = 0.012
"""Metres of the toe joint (HumanML3D joints 10/11) above its box sole when the foot is flat.

The simulated body stands on its soles, so its planted toe joints are this high; HumanML3D's
convention puts the lowest joint (a planted toe) on the floor. :func:`simdiff.sim.project.project`
lowers its rollout by this much so simulated and kinematic motions share one floor."""


def hml_to_world(p: np.ndarray) -> np.ndarray:
    """HumanML3D Y-up points (..., 3) → MuJoCo Z-up world points (..., 3)."""
    return np.asarray(p)[..., [2, 0, 1]]


def world_to_hml(p: np.ndarray) -> np.ndarray:
    """MuJoCo Z-up world points (..., 3) → HumanML3D Y-up points (..., 3)."""
    return np.asarray(p)[..., [1, 2, 0]]


# Per-joint-group (left side) hinge ranges in degrees, (x, y, z); x forward, y left, z up.
# y on legs/trunk is flexion (+ = knee bends / trunk bends forward / toes point down).
_RANGES_DEG: dict[str, tuple[tuple[float, float], ...]] = {
    "Hip": ((-35, 75), (-140, 35), (-50, 50)),
    "Knee": ((-12, 12), (-3, 160), (-12, 12)),
    "Ankle": ((-25, 25), (-45, 70), (-30, 30)),
    "Toe": ((-5, 5), (-75, 30), (-5, 5)),
    "Torso": ((-30, 30), (-30, 50), (-40, 40)),
    "Spine": ((-30, 30), (-30, 50), (-40, 40)),
    "Chest": ((-30, 30), (-30, 50), (-40, 40)),
    "Neck": ((-45, 45), (-45, 60), (-60, 60)),
    "Head": ((-35, 35), (-45, 45), (-60, 60)),
    "Thorax": ((-30, 30), (-30, 30), (-30, 30)),
    "Shoulder": ((-45, 175), (-175, 70), (-95, 95)),
    "Elbow": ((-30, 30), (-155, 5), (-95, 95)),
    "Wrist": ((-70, 70), (-70, 70), (-70, 70)),
    "Hand": ((-30, 30), (-30, 30), (-30, 30)),
}

# (kp N·m/rad, kd N·m·s/rad, force limit N·m) per group; symmetric, same for all 3 axes.
_GAINS: dict[str, tuple[float, float, float]] = {
    "Hip": (800.0, 50.0, 500.0),
    "Knee": (800.0, 50.0, 500.0),
    "Ankle": (1000.0, 40.0, 300.0),
    "Toe": (60.0, 3.0, 80.0),
    "Torso": (800.0, 50.0, 500.0),
    "Spine": (800.0, 50.0, 500.0),
    "Chest": (800.0, 50.0, 500.0),
    "Neck": (200.0, 12.0, 150.0),
    "Head": (100.0, 6.0, 80.0),
    "Thorax": (300.0, 18.0, 200.0),
    "Shoulder": (300.0, 18.0, 200.0),
    "Elbow": (150.0, 9.0, 120.0),
    "Wrist": (40.0, 2.5, 40.0),
    "Hand": (10.0, 1.0, 20.0),
}

# Segment masses in kg (sum 72.0).
_MASSES: dict[str, float] = {
    "Pelvis": 15.4, "Hip": 7.2, "Knee": 3.4, "Ankle": 1.0, "Toe": 0.25, "Torso": 4.4,
    "Spine": 4.0, "Chest": 9.5, "Neck": 1.0, "Head": 4.3, "Thorax": 1.3, "Shoulder": 1.9,
    "Elbow": 1.15, "Wrist": 0.25, "Hand": 0.25,
}


def group_of(body: str) -> str:
    """Joint group of a body name (``"L_Knee"`` → ``"Knee"``)."""
    return body.split("_", 1)[1] if body[:2] in ("L_", "R_") else body


def _side_range(body: str, axis: int) -> tuple[float, float]:
    lo, hi = _RANGES_DEG[group_of(body)][axis]
    if body.startswith("R_") and axis in (0, 2):  # mirror y → −y: x and z rotations flip sign
        lo, hi = -hi, -lo
    return float(np.deg2rad(lo)), float(np.deg2rad(hi))


@dataclass(frozen=True)
class HumanoidConfig:
    """Options of the generated humanoid.

    Attributes:
        timestep: physics step in seconds (1/450).
        gain_scale: multiplies every actuator kp, kd and force limit.
        foot_friction: sliding friction of feet and toes (floor uses the max of the pair).
        hand_friction: sliding friction of wrists and hands.
        body_friction: sliding friction of the other geoms.
        floor_friction: sliding friction of the floor plane.
        ankle_height: ankle joint height above the sole when the foot is flat (m).
        armature: rotor inertia added to every hinge (kg·m²), also stabilises small links.
        joint_damping: passive damping of every hinge (N·m·s/rad).
    """

    timestep: float = 1.0 / 450.0
    gain_scale: float = 1.0
    foot_friction: float = 0.9
    hand_friction: float = 0.9
    body_friction: float = 0.6
    floor_friction: float = 0.5
    ankle_height: float = 0.06
    armature: float = 0.02
    joint_damping: float = 1.0
    extra: tuple[tuple[str, float], ...] = field(default_factory=tuple)


# Rest direction (world frame, left side; x forward, y left, z up) of the bone from each
# body's parent joint to its origin. Chosen from typical standing HumanML3D poses so that
# all-zero hinges is a natural upright stance: trunk slightly curved, head forward-up,
# collars up-lateral, arms hanging down, legs straight, feet flat.
_REST_DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "Hip": (-0.05, 0.56, -0.82), "Knee": (0.0, 0.0, -1.0), "Ankle": (0.0, 0.0, -1.0),
    "Torso": (-0.2, 0.0, 0.98), "Spine": (0.2, 0.0, 0.98), "Chest": (0.7, 0.0, 0.7),
    "Neck": (0.1, 0.0, 1.0), "Head": (0.7, 0.0, 0.7), "Thorax": (0.0, 0.5, 0.87),
    "Shoulder": (0.0, 1.0, 0.0), "Elbow": (0.0, 0.0, -1.0), "Wrist": (0.0, 0.0, -1.0),
}
HAND_LENGTH: float = 0.08
"""Wrist to hand-body distance (m); HumanML3D has no hand joint."""


def _bone_length(body: str) -> float:
    """HumanML3D bone length ending at ``body``'s joint, averaged over left and right (m)."""
    if body[:2] in ("L_", "R_"):
        return 0.5 * float(BONE_LENGTHS[BODY_TO_HML["L_" + body[2:]]] + BONE_LENGTHS[BODY_TO_HML["R_" + body[2:]]])
    return float(BONE_LENGTHS[BODY_TO_HML[body]])


def _rest_offsets(cfg: HumanoidConfig) -> dict[str, np.ndarray]:
    """Offset (world frame at rest, metres) of every body origin from its parent's."""
    offs: dict[str, np.ndarray] = {}
    for body, parent in BODY_PARENT.items():
        g = group_of(body)
        sgn = np.array([1.0, -1.0 if body.startswith("R_") else 1.0, 1.0])
        if parent is None:
            offs[body] = np.zeros(3)
        elif g == "Toe":  # toe joint lower than the ankle so that zero angle = flat foot
            length = _bone_length(body)
            drop = cfg.ankle_height - TOE_JOINT_HEIGHT
            offs[body] = np.array([np.sqrt(length**2 - drop**2), 0.0, -drop])
        elif g == "Hand":
            offs[body] = np.array([0.0, 0.0, -HAND_LENGTH])
        else:
            d = np.array(_REST_DIRECTIONS[g]) * sgn
            offs[body] = d / np.linalg.norm(d) * _bone_length(body)
    return offs


def rest_positions(cfg: HumanoidConfig = HumanoidConfig()) -> dict[str, np.ndarray]:
    """World position of each body origin at rest with the pelvis at the origin."""
    offs = _rest_offsets(cfg)
    pos: dict[str, np.ndarray] = {}
    for body in BODY_NAMES:
        parent = BODY_PARENT[body]
        pos[body] = offs[body] if parent is None else pos[parent] + offs[body]
    return pos


def standing_height(cfg: HumanoidConfig = HumanoidConfig()) -> float:
    """Pelvis height (m) at which the rest pose stands with flat soles on the floor."""
    return float(-rest_positions(cfg)["L_Ankle"][2] + cfg.ankle_height)


def _fmt(v: np.ndarray | list[float] | tuple[float, ...]) -> str:
    return " ".join(f"{float(x):.6g}" for x in v)


def _capsule(a: np.ndarray, b: np.ndarray, radius: float, mass: float, cls: str) -> str:
    return (
        f'<geom class="{cls}" type="capsule" fromto="{_fmt(a)} {_fmt(b)}" size="{radius:.4g}" '
        f'mass="{mass:.4g}"/>'
    )


def _geoms(body: str, offs: dict[str, np.ndarray], cfg: HumanoidConfig) -> list[str]:
    """Geoms of one body, in that body's frame (world-aligned at rest)."""
    g = group_of(body)
    m = _MASSES[g]
    children = [c for c, p in BODY_PARENT.items() if p == body]
    z = np.zeros(3)
    if body == "Pelvis":
        lh, rh = offs["L_Hip"], offs["R_Hip"]
        return [
            _capsule(lh * 0.9 + [0, 0, 0.02], rh * 0.9 + [0, 0, 0.02], 0.09, m * 0.7, "body"),
            _capsule(z + [-0.01, 0, 0.03], offs["Torso"] * 0.8, 0.09, m * 0.3, "body"),
        ]
    if g == "Ankle":  # the foot: a box sole from the heel to just past the toe joint
        toe = offs[body.replace("Ankle", "Toe")]
        sole = -cfg.ankle_height
        x0, x1 = -0.065, toe[0] + 0.01
        half_h = 0.025
        half_w = 0.045
        return [
            f'<geom class="foot" type="box" pos="{_fmt([(x0 + x1) / 2, 0.0, sole + half_h])}" '
            f'size="{_fmt([(x1 - x0) / 2, half_w, half_h])}" mass="{m:.4g}"/>'
        ]
    if g == "Toe":  # toe: a short box in front of the toe joint, sole at the same level
        sole = -TOE_JOINT_HEIGHT
        half_h = TOE_JOINT_HEIGHT
        return [
            f'<geom class="foot" type="box" pos="{_fmt([0.035, 0.0, sole + half_h])}" '
            f'size="{_fmt([0.035, 0.043, half_h])}" mass="{m:.4g}"/>'
        ]
    if g == "Head":
        return [f'<geom class="body" type="sphere" pos="0 0 0.07" size="0.095" mass="{m:.4g}"/>']
    if g == "Hand":
        return [
            f'<geom class="hand" type="box" pos="0 0 -0.045" '
            f'size="0.018 0.045 0.05" mass="{m:.4g}"/>'
        ]
    child = offs[children[0]]
    radius = {
        "Hip": 0.065, "Knee": 0.05, "Torso": 0.08, "Spine": 0.085, "Chest": 0.095, "Neck": 0.045,
        "Thorax": 0.045, "Shoulder": 0.045, "Elbow": 0.035, "Wrist": 0.03,
    }[g]
    cls = "hand" if g == "Wrist" else "body"
    a = child * (0.12 if g in ("Hip", "Knee") else 0.0)
    b = child * (0.88 if g in ("Hip", "Knee", "Shoulder", "Elbow") else 1.0)
    geoms = [_capsule(a, b, radius, m, cls)]
    if g == "Chest":  # shoulder girdle: widen the chest laterally
        geoms = [
            _capsule(z, child * 0.7, radius, m * 0.6, "body"),
            _capsule(
                offs["L_Thorax"] + 0.5 * offs["L_Shoulder"], offs["R_Thorax"] + 0.5 * offs["R_Shoulder"],
                0.065, m * 0.4, "body",
            ),
        ]
    return geoms


def build_mjcf(cfg: HumanoidConfig = HumanoidConfig()) -> str:
    """Generate the humanoid MJCF (an XML string) from the HumanML3D bone lengths.

    Returns:
        An MJCF document with a floor, the 24-body humanoid (free root + 69 hinges) and 69
        PD position actuators, timestep ``cfg.timestep``, implicitfast integrator.
    """
    offs = _rest_offsets(cfg)
    children: dict[str, list[str]] = {b: [] for b in BODY_NAMES}
    for b, p in BODY_PARENT.items():
        if p is not None:
            children[p].append(b)

    lines: list[str] = []

    def emit(body: str, depth: int) -> None:
        ind = "  " * depth
        if body == "Pelvis":
            lines.append(f'{ind}<body name="Pelvis" pos="0 0 {standing_height(cfg):.4f}">')
            lines.append(f'{ind}  <freejoint name="root"/>')
        else:
            lines.append(f'{ind}<body name="{body}" pos="{_fmt(offs[body])}">')
            for axis, name in enumerate("xyz"):
                lo, hi = _side_range(body, axis)
                ax = ["1 0 0", "0 1 0", "0 0 1"][axis]
                lines.append(f'{ind}  <joint name="{body}_{name}" axis="{ax}" range="{lo:.4f} {hi:.4f}"/>')
        for geom in _geoms(body, offs, cfg):
            lines.append(f"{ind}  {geom}")
        for child in children[body]:
            emit(child, depth + 1)
        lines.append(f"{ind}</body>")

    emit("Pelvis", 2)
    acts = []
    for body in BODY_NAMES[1:]:
        kp, kd, fmax = (v * cfg.gain_scale for v in _GAINS[group_of(body)])
        for name in "xyz":
            acts.append(
                f'    <general name="{body}_{name}" joint="{body}_{name}" gainprm="{kp:.6g}" '
                f'biasprm="0 {-kp:.6g} {-kd:.6g}" biastype="affine" forcelimited="true" '
                f'forcerange="{-fmax:.6g} {fmax:.6g}"/>'
            )
    f = cfg
    xml = f"""<mujoco model="simdiff_humanoid">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{f.timestep:.10g}" integrator="implicitfast" solver="Newton" iterations="50"
          cone="pyramidal" gravity="0 0 -9.81"/>
  <size memory="8M"/>
  <default>
    <joint limited="true" damping="{f.joint_damping:.4g}" armature="{f.armature:.4g}"/>
    <geom contype="2" conaffinity="1" condim="3" friction="{f.body_friction:.3g} 0.005 0.0001"
          solref="0.015 1" margin="0"/>
    <default class="body"/>
    <default class="foot"><geom friction="{f.foot_friction:.3g} 0.005 0.0001" rgba="0.8 0.5 0.3 1"/></default>
    <default class="hand"><geom friction="{f.hand_friction:.3g} 0.005 0.0001" rgba="0.8 0.7 0.5 1"/></default>
  </default>
  <worldbody>
    <light pos="0 0 4" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="0 0 0.05" contype="1" conaffinity="2"
          friction="{f.floor_friction:.3g} 0.005 0.0001" rgba="0.7 0.7 0.7 1"/>
{chr(10).join(lines)}
  </worldbody>
  <actuator>
{chr(10).join(acts)}
  </actuator>
</mujoco>
"""
    return xml


@functools.lru_cache(maxsize=8)
def load_model(cfg: HumanoidConfig = HumanoidConfig()):  # -> mujoco.MjModel
    """Compile the generated humanoid (cached per config; treat the result as read-only
    except for ``opt.gravity``, which :class:`simdiff.sim.env.Environment` sets per rollout).
    """
    import mujoco

    return mujoco.MjModel.from_xml_string(build_mjcf(cfg))


@dataclass(frozen=True)
class ModelIndex:
    """Handy ids and arrays of a compiled humanoid.

    Attributes:
        pelvis: body id of the pelvis.
        hml_bodies: (22,) body id of each HumanML3D joint.
        foot_geoms, hand_geoms: geom ids whose floor contact gates the residual.
        floor_geom: id of the floor plane.
        kp, kd: (69,) actuator gains; fmax: (69,) force limits.
        jnt_lo, jnt_hi: (69,) hinge ranges (rad).
        mass: total mass (kg).
    """

    pelvis: int
    hml_bodies: np.ndarray
    foot_geoms: np.ndarray
    hand_geoms: np.ndarray
    support_geoms: np.ndarray
    floor_geom: int
    head: int
    kp: np.ndarray
    kd: np.ndarray
    fmax: np.ndarray
    jnt_lo: np.ndarray
    jnt_hi: np.ndarray
    mass: float


def model_index(model) -> ModelIndex:
    """Build a :class:`ModelIndex` for a compiled humanoid."""
    import mujoco

    def bid(name: str) -> int:
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)

    def geoms_of(names: tuple[str, ...]) -> np.ndarray:
        ids = {bid(n) for n in names}
        return np.array([g for g in range(model.ngeom) if model.geom_bodyid[g] in ids], dtype=int)

    feet, hands = geoms_of(FOOT_BODIES), geoms_of(HAND_BODIES)
    return ModelIndex(
        pelvis=bid("Pelvis"),
        hml_bodies=np.array([bid(BODY_NAMES[i - 1]) for i in HML_BODY_IDS]),
        foot_geoms=feet,
        hand_geoms=hands,
        support_geoms=np.concatenate([feet, hands]),
        floor_geom=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor"),
        head=bid("Head"),
        kp=model.actuator_gainprm[:, 0].copy(),
        kd=-model.actuator_biasprm[:, 2].copy(),
        fmax=model.actuator_forcerange[:, 1].copy(),
        jnt_lo=model.jnt_range[1:, 0].copy(),
        jnt_hi=model.jnt_range[1:, 1].copy(),
        mass=float(model.body_subtreemass[bid("Pelvis")]),
    )
