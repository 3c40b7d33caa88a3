"""Is the simulator left-right symmetric?  rollout(MX, mirror φ) vs mirror(rollout(X, φ)) (issue 13).

Usage:
    nice -n 10 python benchmarks/mirror_check.py --corpus /work/scratch/c12b/corpus3 \
        --out reports/augment/mirror_check.md

For each clip X (and its mirrored copy MX from the same corpus), projects X under φ and MX
under mirror(φ) = (g_z, −w_x, w_y) with the augmentation's settings (flight clock on, root
residual bound 0.5·m·|g_z|, d_L2 on the corpus Mean/Std), and compares mirror(rollout(X))
with rollout(MX): mean joint distance (mm, over the common frames), success agreement, and
the differences of d_L2, pose d_L2 and mean root residual.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

CLIPS = ("03_01_00", "06_01_00", "127_04_00", "02_04_00", "05_16_00", "05_03_00")
ENVS = {"earth": (-9.81, 0.0, 0.0), "wind_x +8 N": (-9.81, 8.0, 0.0),
        "wind_y +8 N": (-9.81, 0.0, 8.0), "g = -3": (-3.0, 0.0, 0.0)}


def main() -> None:
    from simdiff.data.augment.run import load_source_joints
    from simdiff.data.augment.share import mirror_env
    from simdiff.motion.mirror import mirror_joints
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.humanoid import HumanoidConfig, load_model
    from simdiff.sim.project import project
    from simdiff.sim.residual import ResidualConfig

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--corpus", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--clips", nargs="*", default=list(CLIPS))
    args = ap.parse_args()
    norm = Normalizer.from_dir(str(args.corpus))
    model = load_model(HumanoidConfig())
    kw = dict(model=model, residual=ResidualConfig(max_force=0.5), normalizer=norm, flight=FlightConfig())
    rows, t0 = [], time.time()
    for clip in args.clips:
        x, mx = load_source_joints(args.corpus, clip), load_source_joints(args.corpus, "M" + clip)
        src_mm = float(np.linalg.norm(mirror_joints(x)[: len(mx)] - mx[: len(x)], axis=-1).mean() * 1e3)
        for name, phi in ENVS.items():
            env = Environment(*phi)
            ox, ix = project(x, env, **kw)
            om, im = project(mx, mirror_env(env), **kw)
            n = min(len(ox), len(om))
            mm = float(np.linalg.norm(mirror_joints(ox)[:n] - om[:n], axis=-1).mean() * 1e3)
            oe, ie = project(mirror_joints(x), mirror_env(env), **kw)  # the exact mirror of X as input
            ne = min(len(ox), len(oe))
            exact_mm = float(np.linalg.norm(mirror_joints(ox)[:ne] - oe[:ne], axis=-1).mean() * 1e3)
            rows.append(dict(clip=clip, env=name, src_mm=src_mm, mm=mm, exact_mm=exact_mm, exact_n=(len(ox), len(oe)),
                             exact_ok=ie.success, n=(len(ox), len(om)),
                             ok=(ix.success, im.success), dl2=(ix.d_l2, im.d_l2), pose=(ix.d_l2_pose, im.d_l2_pose),
                             res=(ix.residual.get("force_mean_mg", math.nan), im.residual.get("force_mean_mg", math.nan))))
            print(rows[-1], flush=True)
    lines = ["# Mirror symmetry of the simulator (issue 13)", "",
             f"Command: `nice -n 10 python benchmarks/mirror_check.py --corpus {args.corpus} --out {args.out}`", "",
             "X projected under φ, MX (the corpus's mirrored copy) under mirror(φ) = (g_z, −w_x, w_y); flight clock on,",
             "residual bound 0.5, d_L2 on the corpus Mean/Std. `src mm`: mean joint distance of mirror(X) to MX as the",
             "corpus stores them (MX is retargeted to the canonical skeleton, so they already differ);",
             "`mm`: mean joint distance of mirror(rollout(X)) to rollout(MX) over the common frames;",
             "`exact mm`: mirror(rollout(X)) vs rollout(mirror(X)) under mirror(φ) (the simulator's own symmetry,",
             "same input up to the reflection), `exact ok`: success of that rollout.", "",
             "| clip | φ | src mm | mm | exact mm | exact frames | exact ok | frames X/MX | success X/MX | d_L2 X/MX | pose d_L2 X/MX | residual X/MX |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['clip']} | {r['env']} | {r['src_mm']:.1f} | {r['mm']:.1f} | {r['exact_mm']:.2f} | "
                     f"{r['exact_n'][0]}/{r['exact_n'][1]} | {r['exact_ok']} | {r['n'][0]}/{r['n'][1]} | "
                     f"{r['ok'][0]}/{r['ok'][1]} | {r['dl2'][0]:.3f}/{r['dl2'][1]:.3f} | "
                     f"{r['pose'][0]:.3f}/{r['pose'][1]:.3f} | {r['res'][0]:.4f}/{r['res'][1]:.4f} |")
    mm = np.array([r["mm"] for r in rows])
    agree = sum(r["ok"][0] == r["ok"][1] for r in rows)
    ex = np.array([r["exact_mm"] for r in rows])
    ex_agree = sum(r["ok"][0] == r["exact_ok"] and r["exact_n"][0] == r["exact_n"][1] for r in rows)
    lines += ["", f"Pairs: {len(rows)}; mean joint distance {mm.mean():.1f} mm (median {np.median(mm):.1f}, max {mm.max():.1f});"
              f" success agrees in {agree}/{len(rows)}.",
              f"Exact mirror input: mean joint distance {ex.mean():.3f} mm (max {ex.max():.3f});"
              f" success and length agree in {ex_agree}/{len(rows)}; wall {time.time() - t0:.0f} s.", ""]
    args.out.write_text("\n".join(lines), encoding="utf-8")
    print("\n".join(lines[-3:]))


if __name__ == "__main__":
    main()
