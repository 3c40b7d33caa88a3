"""Inverse kinematics on a rigid skeleton: bring the joints a user gave onto their targets, bones kept.

:func:`simdiff.motion.rigid.fit` keeps bone directions, so a joint given without its whole pose (a wrist alone, a
kept upper body above new legs) ends where its chain's lengths put it, centimetres off. :func:`reach` corrects the
fitted rotations (as global rotations) and moves the root, all frames at once, to minimise (in this order of weight)

* the distance of every given coordinate from its target (growing only linearly beyond :data:`REACH`);
* the acceleration the correction adds to the joints;
* how far the joints nobody gave move from where the fit put them (so planted feet stay planted);
* how fast the corrections change from frame to frame (so a lone keyframe bends its neighbours too, no speed spike);
* the size of the rotation corrections.

The skeleton's offsets are not touched: bone lengths stay exact. Shapes: (T, 22, 3) metres, Y up, 20 fps.
"""

from __future__ import annotations

import numpy as np
import torch
from torch import Tensor

from simdiff.motion.rigid import RigidMotion, global_rotations
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT, NUM_JOINTS, PARENTS

TARGET_SCALE: float = 0.001
"""m: a given coordinate this far from its target costs as much as one :data:`HOLD_SCALE` of a free joint."""
REACH: float = 0.05
"""m: beyond this a target's pull stops growing (pseudo-Huber), so a target out of the body's reach is neared
smoothly, not met by a one-frame jump (an ankle 3 m ahead of the body at frame 0 moved it at 37 m/s)."""
ACCELERATION_SCALE: float = 0.02
"""m per frame² (8 m/s²): the change a correction makes to a joint's acceleration that costs one unit."""
HOLD_SCALE: float = 0.05
"""m: the free joints' movement from the fit that costs one unit."""
FOOT_HOLD_SCALE: float = 0.005
"""m: the same for free ankles and toes, whose contacts with the floor must survive a pull elsewhere (at
:data:`HOLD_SCALE` a wrist pulled 15 cm dragged the feet of a walk 4 cm)."""
ROTATION_STEP_SCALE: float = 0.05
"""rad per frame: the change of a rotation correction between neighbouring frames that costs one unit."""
ROOT_STEP_SCALE: float = 0.01
"""m per frame: the same for the root's correction."""
ROTATION_SCALE: float = 1.0
"""rad: the rotation correction that costs one unit (keeps frames without targets well posed)."""
MET: float = 0.0005
"""m: when every given coordinate is already this close (whole poses the fit met), nothing is solved."""
ITERATIONS: int = 100
"""L-BFGS iterations at most: enough for a lone wrist 15 cm off (0.7 mm left) and for a kept walk's legs under a new
wave (3 mm), 0.5 s for 196 frames on 2 cores."""


def _rodrigues(v: Tensor) -> Tensor:
    """Rotation matrices (..., 3, 3) of axis-angle vectors (..., 3) (smooth at 0)."""
    theta2 = (v * v).sum(-1, keepdim=True)[..., None] + 1e-12
    theta = theta2.sqrt()
    x, y, z = v.unbind(-1)
    zero = torch.zeros_like(x)
    k = torch.stack([torch.stack([zero, -z, y], -1), torch.stack([z, zero, -x], -1),
                     torch.stack([-y, x, zero], -1)], -2)
    eye = torch.eye(3, dtype=v.dtype, device=v.device)
    return eye + torch.sin(theta) / theta * k + (1.0 - torch.cos(theta)) / theta2 * (k @ k)


def _ancestry() -> np.ndarray:
    """(22, 21) 0/1: entry [j, k - 1] is 1 when bone k (parent(k) → k) lies on the path from the root to joint j."""
    out = np.zeros((NUM_JOINTS, NUM_JOINTS - 1))
    for j in range(1, NUM_JOINTS):
        k = j
        while k > 0:
            out[j, k - 1] = 1.0
            k = PARENTS[k]
    return out


def reach(motion: RigidMotion, targets: np.ndarray, iterations: int = ITERATIONS) -> RigidMotion:
    """``motion`` with its rotations and root corrected towards ``targets`` (T, 22, 3), NaN = free (any single
    coordinate may be free, e.g. a root path's y). Unchanged when nothing is given or everything given is met
    within :data:`MET`; a target out of the skeleton's reach ends as near as the weights allow."""
    targets = np.asarray(targets, dtype=np.float64)
    given_np = np.isfinite(targets)
    if targets.shape != motion.root.shape[:1] + (NUM_JOINTS, 3):
        raise ValueError(f"targets must be {(len(motion.root), NUM_JOINTS, 3)}, got {targets.shape}")
    if not given_np.any():
        return motion
    cpu = torch.device("cpu")
    glob0 = torch.as_tensor(global_rotations(motion.local), dtype=torch.float64, device=cpu)  # (T, 22, 3, 3)
    root0 = torch.as_tensor(motion.root, dtype=torch.float64, device=cpu)
    offsets = torch.as_tensor(motion.offsets[1:], dtype=torch.float64, device=cpu)  # (21, 3)
    parents = list(PARENTS[1:])
    ancestry = torch.as_tensor(_ancestry(), dtype=torch.float64, device=cpu)
    given = torch.as_tensor(given_np, device=cpu)
    goal = torch.as_tensor(np.nan_to_num(targets), dtype=torch.float64, device=cpu)
    hold = torch.full((NUM_JOINTS, 1), 1.0 / HOLD_SCALE, dtype=torch.float64, device=cpu)
    hold[list(FOOT_LEFT + FOOT_RIGHT)] = 1.0 / FOOT_HOLD_SCALE
    free = (~given) * hold

    def positions(glob: Tensor, root: Tensor) -> Tensor:
        bones = (glob[:, parents] @ offsets[:, :, None])[..., 0]  # (T, 21, 3): each bone in the world
        return root[:, None] + ancestry @ bones

    with torch.no_grad():
        start = positions(glob0, root0)
    if float(((start - goal) * given).abs().max()) < MET:
        return motion
    # corrections of the global rotations: turning the pelvis leaves the spine's orientation alone, which made
    # L-BFGS converge in 100 iterations where local corrections needed over 1,000 (a kept walk's legs under a wave)
    turn = torch.zeros(glob0.shape[:2] + (3,), dtype=torch.float64, device=cpu, requires_grad=True)
    shift = torch.zeros_like(root0, requires_grad=True)
    optimiser = torch.optim.LBFGS([turn, shift], max_iter=iterations, line_search_fn="strong_wolfe",
                                  tolerance_grad=1e-10, tolerance_change=1e-14, history_size=20)

    def loss() -> Tensor:
        optimiser.zero_grad()
        pos = positions(_rodrigues(turn) @ glob0, root0 + shift)
        miss = (((pos - goal) * given) / REACH).pow(2).sum(-1)  # (T, 22), in units of REACH²
        value = (2.0 * (REACH / TARGET_SCALE) ** 2 * ((1.0 + miss).sqrt() - 1.0)).sum()
        bend = torch.diff(pos - start, n=2, dim=0)  # what the correction adds to the joints' accelerations
        value = value + (bend / ACCELERATION_SCALE).pow(2).sum()
        value = value + ((pos - start) * free).pow(2).sum()
        value = value + (torch.diff(turn, dim=0) / ROTATION_STEP_SCALE).pow(2).sum()
        value = value + (torch.diff(shift, dim=0) / ROOT_STEP_SCALE).pow(2).sum()
        value = value + (turn / ROTATION_SCALE).pow(2).sum()
        value.backward()
        return value

    optimiser.step(loss)
    with torch.no_grad():
        glob = (_rodrigues(turn) @ glob0).numpy()
        root = (root0 + shift).numpy()
    local = np.array(motion.local, dtype=np.float64, copy=True)  # leaves keep their local rotation
    local[:, 0] = glob[:, 0]
    for j in set(PARENTS[1:]) - {-1, 0}:
        local[:, j] = np.swapaxes(glob[:, PARENTS[j]], -1, -2) @ glob[:, j]
    return RigidMotion(local, root, motion.offsets)
