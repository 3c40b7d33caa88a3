"""Rule 19's stage B table: python rule19_table.py DIR [DIR ...] (model_check reports; the first is the baseline).
Per report: R@3, FID (mean and per seed), skate ratio vs 2 x GT, own-floor sliding, jump fraction, walk and run
medians, and rule 19's verdicts against the first report."""
import json
import sys
from pathlib import Path


def row(d: str) -> dict:
    rep = json.loads((Path(d) / "check.json").read_text())
    f, seeds = rep["figures"], rep["test_split"]["per_seed"]["generated"]
    return dict(name=Path(d).name, r3=f["r_precision_top3"], fid=f["fid"], fid_seeds=[s["fid"] for s in seeds],
                skate=f["skate_ratio"], skate_bar=2 * f["gt_skate_ratio"], slide=f["sliding_own_floor"],
                jump=f["jump_fraction"], walk=f["walk_median"], run=f["run_median"],
                walk_iqr=(f["walk_corpus_q1"], f["walk_corpus_q3"]), run_q1=f["run_corpus_q1"])


def main() -> None:
    base, *rest = [row(d) for d in sys.argv[1:]]
    print("| setting | R@3 | FID (seed 0 / 1) | skate (bar) | sliding | jumps | walk | run | guards | gain |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in [base, *rest]:
        guards = (r["r3"] >= base["r3"] - 0.01 - 1e-9 and r["slide"] <= 1.0 and r["skate"] <= r["skate_bar"]
                  and r["walk_iqr"][0] <= r["walk"] <= r["walk_iqr"][1] and r["jump"] >= base["jump"] - 0.03 - 1e-9)
        paired = all(a < b for a, b in zip(r["fid_seeds"], base["fid_seeds"]))
        paired_le = all(a <= b for a, b in zip(r["fid_seeds"], base["fid_seeds"]))
        gain = (r["fid"] <= 0.9 * base["fid"] and paired) or (r["run"] >= r["run_q1"] and paired_le)
        seeds = " / ".join(f"{v:.2f}" for v in r["fid_seeds"])
        print(f"| {r['name']} | {r['r3']:.3f} | {r['fid']:.2f} ({seeds}) | {r['skate']:.3f} ({r['skate_bar']:.3f}) | "
              f"{r['slide']:.3f} | {r['jump']:.3f} | {r['walk']:.2f} | {r['run']:.2f} | "
              f"{'pass' if guards else 'FAIL'} | {'-' if r is base else ('yes' if gain else 'no')} |")


if __name__ == "__main__":
    main()
