"""simdiff.motion.floor: clips put on the floor as HumanML3D puts its own."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.features import features_to_joints, joints_to_features
from simdiff.motion.floor import drop_floating, floor_offset, place_on_floor
from simdiff.motion.synthetic import jump, walk


def _features(joints: np.ndarray) -> torch.Tensor:
    return torch.from_numpy(joints_to_features(joints))


def test_a_raised_clip_comes_down_by_exactly_its_lift() -> None:
    base = _features(walk(40))
    lifted = base.clone()
    lifted[:, 3] += 0.7  # root height
    lifted[:, 5:67:3] += 0.7  # every joint's height: the same clip 0.7 m up
    j0, j1 = features_to_joints(base.double()), features_to_joints(lifted.double())
    assert torch.allclose(j1[..., 1] - j0[..., 1], torch.full_like(j0[..., 1], 0.7), atol=1e-5)
    assert float(floor_offset(lifted)) == pytest.approx(float(floor_offset(base)) + 0.7, abs=1e-5)
    placed = place_on_floor(lifted)
    assert placed.dtype == lifted.dtype and placed.shape == lifted.shape
    jp = features_to_joints(placed.double())
    assert float(jp[..., 1].min()) == pytest.approx(0.0, abs=1e-6)
    assert torch.allclose(jp[..., [0, 2]], j1[..., [0, 2]], atol=1e-6)  # nothing moves sideways
    same = [c for c in range(263) if c != 3 and not (5 <= c < 67 and (c - 5) % 3 == 0)]
    assert torch.equal(placed[:, same], lifted[:, same])  # rotations, velocities, contacts untouched


def test_batches_respect_lengths_and_keep_padding() -> None:
    a, b = _features(jump(60, height=0.4, start=20)), _features(walk(60))
    b[:, 3] += 0.3
    b[:, 5:67:3] += 0.3
    b[45:, 3] -= 1.0  # padding frames deep below the floor must not set the offset
    b[45:, 5:67:3] -= 1.0
    batch = torch.stack([a, b])
    lengths = torch.tensor([59, 45])
    off = floor_offset(batch, lengths)
    assert off.shape == (2,) and float(off[1]) > 0.25
    placed = place_on_floor(batch, lengths)
    assert torch.equal(placed[1, 45:], batch[1, 45:])
    low = features_to_joints(placed.double())[..., 1].amin(-1)
    assert float(low[0, :59].min()) == pytest.approx(0.0, abs=1e-6) and float(low[1, :45].min()) == pytest.approx(0.0, abs=1e-6)
    # a jump keeps its flight: the apex over the stance is the same after the shift
    ja, jb = features_to_joints(batch[0].double()), features_to_joints(placed[0].double())
    assert float(ja[:, 0, 1].max() - ja[:, 0, 1].min()) == pytest.approx(float(jb[:, 0, 1].max() - jb[:, 0, 1].min()))


def _raised(f: torch.Tensor, metres: float) -> torch.Tensor:
    out = f.clone()
    out[:, 3] += metres
    out[:, 5:67:3] += metres
    return out


def test_drop_floating_moves_only_clips_that_never_touch_the_floor() -> None:
    from simdiff.motion.metrics import never_touches

    base = place_on_floor(_features(walk(40)))
    batch = torch.stack([_raised(base, 0.05), _raised(base, 1.2), _raised(base, 0.11)])  # touches, floats, floats
    assert never_touches(features_to_joints(batch.double())).tolist() == [False, True, True]
    dropped = drop_floating(batch)
    assert dropped.dtype == batch.dtype and torch.equal(dropped[0], batch[0])  # a touching clip bit for bit
    low = features_to_joints(dropped.double())[..., 1].amin(dim=(-1, -2))
    assert low.tolist() == pytest.approx([0.05, 0.0, 0.0], abs=1e-5)
    assert not never_touches(features_to_joints(dropped.double())).any()
    assert torch.equal(drop_floating(dropped), dropped)  # idempotent
    # only the valid frames decide: a clip touching the floor only in its padding is dropped
    padded = _raised(base, 0.5)
    padded[30:, 3] -= 0.5
    padded[30:, 5:67:3] -= 0.5
    out = drop_floating(padded[None], torch.tensor([30]))[0]
    assert float(floor_offset(out[:30])) == pytest.approx(0.0, abs=1e-6) and torch.equal(out[30:], padded[30:])


def test_the_foot_cleanup_drops_a_floating_clip_and_only_when_on() -> None:
    from simdiff.motion.foot_lock import clean_feet

    base = place_on_floor(_features(walk(40)))
    floating = _raised(base, 0.8)
    assert float(floor_offset(clean_feet(floating))) == pytest.approx(0.0, abs=1e-6)
    assert float(floor_offset(clean_feet(floating, strength=0.0))) == pytest.approx(0.8 + float(floor_offset(base)), abs=1e-5)
    on_floor = clean_feet(base)
    assert float(floor_offset(on_floor)) < 0.10  # a clip on the floor is cleaned as before, not shifted


def test_bad_shape_is_one_line() -> None:
    with pytest.raises(SimdiffError, match="place_on_floor needs"):
        place_on_floor(torch.zeros(10, 200))
    with pytest.raises(SimdiffError, match="drop_floating needs"):
        drop_floating(torch.zeros(10, 200))
