"""Rule 36's stage-B table: python stage_b.py BASE NAME... (eval11/B_<name>/check.json under /work/scratch/s39).
Prints per run: jumps (of 96) and per prompt, R@3 and FID under evaluators 1/2/3 (mean of seeds 0 1), own-floor
sliding, skate ratio (GT), walk / run medians (corpus IQR), and rule 36's stage-B verdict against BASE."""
import json
import sys

ROOT = "/work/scratch/s39/eval11"


def load(name: str) -> dict:
    d = json.load(open(f"{ROOT}/B_{name}/check.json"))
    ts = d["test_split"]
    evals = [ts["generated"]] + [m["generated"] for m in ts.get("more_evaluators", [])]
    f = d["figures"]
    return {"name": name, "jumps": d["jumps"]["overall"]["jumps"],
            "per_prompt": [p["jumps"] for p in d["jumps"]["per_prompt"]],
            "r3": [e["r_precision_top3"]["mean"] for e in evals], "fid": [e["fid"]["mean"] for e in evals],
            "slide": f["sliding_own_floor"], "skate": f["skate_ratio"], "gt_skate": f["gt_skate_ratio"],
            "walk": (f["walk_median"], f["walk_corpus_q1"], f["walk_corpus_q3"]),
            "run": (f["run_median"], f["run_corpus_q1"], f["run_corpus_q3"])}


def verdict(c: dict, b: dict) -> list[str]:
    fails = []
    if c["jumps"] < b["jumps"] + 10:
        fails.append(f"jumps {c['jumps']} < {b['jumps'] + 10}")
    if c["r3"][0] < b["r3"][0] - 0.015:
        fails.append(f"R@3 e1 {c['r3'][0]:.3f} < {b['r3'][0] - 0.015:.3f}")
    if sum(c["r3"]) / 3 < sum(b["r3"]) / 3 - 0.015:
        fails.append(f"mean R@3 {sum(c['r3']) / 3:.3f} < {sum(b['r3']) / 3 - 0.015:.3f}")
    if c["fid"][0] > 1.10 * b["fid"][0]:
        fails.append(f"FID e1 {c['fid'][0]:.2f} > {1.10 * b['fid'][0]:.2f}")
    if not any(c["fid"][i] <= 1.10 * b["fid"][i] for i in (1, 2)):
        fails.append("FID e2 and e3 both > 1.10 x base")
    if c["slide"] > 1.0 or c["skate"] > 2 * c["gt_skate"]:
        fails.append("sliding/skate")
    for k in ("walk", "run"):
        m, q1, q3 = c[k]
        if not q1 <= m <= q3:
            fails.append(f"{k} {m:.2f} outside [{q1:.2f}, {q3:.2f}]")
    return fails


def main() -> None:
    rows = [load(n) for n in sys.argv[1:]]
    base = rows[0]
    print("| run | jumps (fwd/in place/one leg/up-down/both feet/long) | R@3 e1/e2/e3 | FID e1/e2/e3 | sliding | skate (GT) "
          "| walk / run m/s | rule 36 B |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        v = "base" if r is base else ("pass" if not verdict(r, base) else "FAIL: " + "; ".join(verdict(r, base)))
        print(f"| {r['name']} | {r['jumps']} ({'/'.join(map(str, r['per_prompt']))}) | "
              f"{'/'.join(f'{x:.3f}' for x in r['r3'])} | {'/'.join(f'{x:.2f}' for x in r['fid'])} | {r['slide']:.3f} | "
              f"{r['skate']:.3f} ({r['gt_skate']:.3f}) | {r['walk'][0]:.2f} / {r['run'][0]:.2f} | {v} |")


if __name__ == "__main__":
    main()
