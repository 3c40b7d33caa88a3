"""Tests for simdiff.motion.metrics (CLoSD joint-based physics metrics, GMD skate ratio)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.metrics import per_sample_physics_metrics, physics_metrics


def standing(frames: int, lowest: float) -> np.ndarray:
    """(T, 22, 3) body whose lowest joint (joint 10, left toe) sits at y = ``lowest``."""
    joints = np.zeros((frames, 22, 3), dtype=np.float32)
    joints[..., 1] = lowest + 0.5 + 0.01 * np.arange(22)
    joints[:, 10, 1] = lowest
    joints[:, 11, 1] = lowest + 0.003
    return joints


def reference(joints: np.ndarray, lengths: list[int]) -> dict[str, float]:
    """Straight loop over the CLoSD formulas (facts sheet section 4.2)."""
    pen, flo, sli = [], [], []
    for x, n in zip(joints.astype(np.float64), lengths):
        for t in range(n):
            h = x[t, :, 1].min()
            pen.append(max(0.0, -(h + 0.005)) * 1000)
            flo.append(max(0.0, h - 0.005) * 1000)
        for t in range(n - 1):
            c = int(np.argmin(x[t, :, 1]))
            if x[t, c, 1] <= 0.005 and x[t + 1, c, 1] <= 0.005:
                sli.append(np.linalg.norm(x[t + 1, c, [0, 2]] - x[t, c, [0, 2]]) * 1000)
            else:
                sli.append(0.0)
    return {"penetration": np.mean(pen), "floating": np.mean(flo), "sliding": np.mean(sli)}


def test_hovering_body_floats_15mm() -> None:
    m = physics_metrics(standing(30, 0.02))
    assert m["floating"] == pytest.approx(15.0, abs=1e-4)
    assert m["penetration"] == 0.0
    assert m["sliding"] == 0.0
    assert m["skate_ratio"] == 0.0


def test_sinking_body_penetrates() -> None:
    m = physics_metrics(standing(30, -0.025))
    assert m["penetration"] == pytest.approx(20.0, abs=1e-4)
    assert m["floating"] == 0.0
    # Within the 5 mm tolerance nothing counts.
    m = physics_metrics(standing(30, -0.004))
    assert m["penetration"] == 0.0 and m["floating"] == 0.0


def test_sliding_foot_at_known_speed() -> None:
    joints = standing(21, 0.0)
    # Lowest joint slides along x at 0.3 m/s = 15 mm/frame, and 20 mm/frame along z: 25 mm.
    joints[:, 10, 0] = 0.015 * np.arange(21)
    joints[:, 10, 2] = 0.020 * np.arange(21)
    m = physics_metrics(joints)
    assert m["sliding"] == pytest.approx(25.0, abs=1e-3)
    # Lift the foot above 5 mm in the second half: pairs 10..19 no longer count.
    joints[11:, :, 1] += 0.006
    per = per_sample_physics_metrics(joints)
    assert per["sliding"][0] == pytest.approx(25.0 * 10 / 20, abs=1e-3)


def test_lengths_mask_the_padding() -> None:
    good = standing(40, 0.0)
    bad = good.copy()
    bad[20:, :, 1] += 1.0  # garbage after frame 20 ...
    bad[20:, :, 0] += np.arange(20)[:, None]
    m = physics_metrics(np.stack([good, bad]), lengths=[40, 20])  # ... masked out
    assert m == {"penetration": 0.0, "floating": 0.0, "sliding": 0.0, "skate_ratio": 0.0}
    unmasked = physics_metrics(np.stack([good, bad]))
    assert unmasked["floating"] == pytest.approx(995.0 * 20 / 80, abs=1e-2)
    # Pooled over frames (CLoSD), not a mean of per-sample means.
    hover = standing(40, 0.02)
    m = physics_metrics(np.stack([hover, good]), lengths=[10, 40])
    assert m["floating"] == pytest.approx(15.0 * 10 / 50, abs=1e-4)
    per = per_sample_physics_metrics(np.stack([hover, good]), lengths=torch.tensor([10, 40]))
    np.testing.assert_allclose(per["floating"], [15.0, 0.0], atol=1e-4)


def test_matches_reference_loop_on_random_batch() -> None:
    rng = np.random.default_rng(3)
    joints = rng.normal(0.0, 0.02, size=(6, 30, 22, 3)).astype(np.float32)
    joints[..., 1] = np.abs(joints[..., 1]) * 0.5 - 0.008
    joints[:, ::3, :, 1] += 0.02  # every third frame hovers
    joints[..., [0, 2]] += np.cumsum(rng.normal(0, 0.01, size=(6, 30, 1, 2)), axis=1).astype(np.float32)
    lengths = [30, 12, 2, 25, 30, 7]
    got = physics_metrics(torch.from_numpy(joints), lengths=lengths)
    want = reference(joints, lengths)
    assert min(want.values()) > 0.1  # every metric is exercised
    for key in ("penetration", "floating", "sliding"):
        assert got[key] == pytest.approx(want[key], rel=1e-5, abs=1e-5)


def test_skate_ratio_on_constructed_skating_foot() -> None:
    frames = 21  # 20 frame pairs
    joints = standing(frames, 0.0)
    joints[:, 11, 1] = 0.3  # right foot in the air
    # Left foot: still for pairs 0..9, then slides at 1 m/s (0.05 m/frame) for pairs 10..19.
    x = np.zeros(frames)
    x[11:] = 0.05 * np.arange(1, 11)
    joints[:, 10, 0] = x
    per = per_sample_physics_metrics(joints)
    # Speed > 0.5 from pair 10; the 5-pair centred mean at pair 10 is 3/5 * 1 m/s = 0.6 > 0.5,
    # and at pair 19 (2 zero-padded neighbours) 3/5 m/s too: pairs 10..19 skate.
    assert per["skate_ratio"][0] == pytest.approx(10 / 20)
    # At 0.8 m/s the mean at the edges is 0.48 < 0.5: pairs 11..18 only.
    joints[:, 10, 0] = x * 0.8
    assert per_sample_physics_metrics(joints)["skate_ratio"][0] == pytest.approx(8 / 20)
    # Raising the foot to 5 cm (not below 0.05 m) removes the contact.
    joints[:, 10, 1] = 0.05
    assert per_sample_physics_metrics(joints)["skate_ratio"][0] == 0.0


def test_skate_ratio_respects_lengths_and_aggregates_by_sample() -> None:
    frames = 21
    joints = standing(frames, 0.0)
    joints[:, 11, 1] = 0.3
    joints[:, 10, 0] = 0.05 * np.arange(frames)  # 1 m/s skating throughout
    batch = np.stack([joints, standing(frames, 0.0)])
    per = per_sample_physics_metrics(batch, lengths=[11, 21])
    # 10 pairs, all skating; the window's zero padding sits beyond the valid pairs, so the
    # last two pairs have a mean of 3/5 and 4/5 m/s, still > 0.5.
    np.testing.assert_allclose(per["skate_ratio"], [1.0, 0.0])
    assert physics_metrics(batch, lengths=[11, 21])["skate_ratio"] == pytest.approx(0.5)


def test_bad_input_errors() -> None:
    with pytest.raises(SimdiffError, match=r"\(4, 21, 3\)"):
        physics_metrics(np.zeros((4, 21, 3)))
    with pytest.raises(SimdiffError, match=r"lengths\[1\]=50"):
        physics_metrics(np.zeros((2, 40, 22, 3)), lengths=[40, 50])
    with pytest.raises(SimdiffError, match="3 entries"):
        physics_metrics(np.zeros((3, 40, 22, 3)), lengths=[40, 40])
    with pytest.raises(SimdiffError, match=r"lengths\[0\]=1"):
        physics_metrics(np.zeros((1, 40, 22, 3)), lengths=[1])


def test_own_floor_sliding_sees_the_skating_of_a_hovering_motion() -> None:
    from simdiff.motion.metrics import own_floor_metrics

    skating = standing(40, 0.0)
    skating[:, :, 0] += 0.004 * np.arange(40)[:, None]  # the whole body slides 4 mm per frame
    hovering = skating.copy()
    hovering[..., 1] += 0.02  # the same, 2 cm up: CLoSD sees no contact
    assert physics_metrics(hovering)["sliding"] == 0.0
    own = own_floor_metrics(hovering)
    assert own["sliding_own_floor"] == pytest.approx(4.0, rel=1e-5)
    assert own["own_floor"] == pytest.approx(20.0, abs=1e-3)
    # on y = 0 the two slidings agree, and the own floor is 0
    on_floor = own_floor_metrics(skating)
    assert on_floor["sliding_own_floor"] == pytest.approx(physics_metrics(skating)["sliding"])
    assert on_floor["own_floor"] == pytest.approx(0.0, abs=1e-6)
    # per motion and pooled over valid pairs: a batch of one hovering and one on the floor, second cut short
    batch = np.stack([hovering, skating])
    both = own_floor_metrics(batch, [40, 11])
    assert both["sliding_own_floor"] == pytest.approx(4.0, rel=1e-5)
    assert both["own_floor"] == pytest.approx(10.0, abs=1e-3)
    # a motion that jumps keeps its stance as its floor (the 5th percentile, not the mean)
    jump = hovering.copy()
    jump[15:25, :, 1] += 0.3
    assert own_floor_metrics(jump)["own_floor"] == pytest.approx(20.0, abs=1e-3)


def test_centred_mean_is_scipys_constant_mode_uniform_filter() -> None:
    from scipy.ndimage import uniform_filter1d

    from simdiff.motion.metrics import centred_mean

    rng = np.random.default_rng(0)
    for shape in [(3, 1, 2), (2, 4, 2), (5, 120, 2)]:
        x = rng.random(shape)
        for size in (1, 3, 5, 7):
            want = uniform_filter1d(x, size=size, axis=1, mode="constant", cval=0.0)
            np.testing.assert_allclose(centred_mean(x, size), want, atol=1e-12)
    with pytest.raises(SimdiffError, match="odd window, got 4"):
        centred_mean(np.zeros((1, 5, 2)), 4)


def test_never_touches_the_floor_only_when_every_valid_frame_is_clear() -> None:
    from simdiff.motion.metrics import FLOOR_CLEARANCE, never_touches

    assert FLOOR_CLEARANCE == 0.10
    afloat = standing(40, 0.5)  # lowest joint 0.5 m up all clip long
    landing = afloat.copy()
    landing[30:, :, 1] -= 0.45  # comes down to 5 cm in its last 10 frames
    grazing = standing(40, 0.10)  # exactly at the clearance: touches
    batch = np.stack([afloat, landing, grazing, standing(40, 0.0)])
    assert never_touches(batch).tolist() == [True, False, False, False]
    assert never_touches(batch, [40, 30, 40, 40]).tolist() == [True, True, False, False]  # the landing is padding
    assert never_touches(afloat).tolist() == [True]  # one motion (T, 22, 3)
    assert never_touches(torch.from_numpy(batch), clearance=0.6).tolist() == [False] * 4


def test_glides_only_when_the_body_travels_on_feet_that_never_lift() -> None:
    from simdiff.motion.metrics import GLIDE_LIFT, GLIDE_SPEED, glides
    from simdiff.motion.synthetic import walk

    assert (GLIDE_SPEED, GLIDE_LIFT) == (0.5, 0.05)
    statue = standing(60, 0.0)
    statue[..., 0] += np.linspace(0.0, 6.0, 60)[:, None]  # carried 6 m in 3 s (2 m/s), no joint moves otherwise
    slow = standing(60, 0.0)
    slow[..., 0] += np.linspace(0.0, 0.6, 60)[:, None]  # 0.2 m/s: a shuffle, not a glide
    gait = walk(60, speed=1.4)  # travels and lifts its feet
    batch = np.stack([statue, slow, gait, standing(60, 0.0)])
    assert glides(batch).tolist() == [True, False, False, False]
    assert glides(torch.from_numpy(statue)).tolist() == [True]
    late = statue.copy()
    late[40:, 7, 1] += 0.3  # a foot lifts only after frame 40
    assert glides(np.stack([late, late]), [40, 60]).tolist() == [True, False]
    with pytest.raises(SimdiffError, match=r"lengths\[0\]=1 is outside \[2, 60\]"):
        glides(np.stack([statue, statue]), [1, 60])
