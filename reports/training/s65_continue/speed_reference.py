"""The model check's speed references on corpus3 at sample lengths 60 and 120 (length-matched) and over all lengths,
and the shipped test check's sample medians (session 65). python speed_reference.py CORPUS3 > speed_reference.txt"""
import json, sys
from simdiff.eval.model_check.detect import quartiles
from simdiff.eval.model_check.prompts import corpus_clips, length_matched
clips = corpus_clips(sys.argv[1], ["walk", "run"], 0, 0, 120)
for kind, rows in clips.items():
    sp, fr = [r[0] for r in rows], [r[2] for r in rows]
    for L in (60, 120):
        q, a = quartiles([sp[i] for i in length_matched(fr, L)]), quartiles(sp)
        print(f"{kind} L {L}: matched n {q['n']} q1 {q['q1']:.2f} med {q['median']:.2f} q3 {q['q3']:.2f} | "
              f"all n {a['n']} q1 {a['q1']:.2f} med {a['median']:.2f} q3 {a['q3']:.2f}")
rep = json.load(open("reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json"))
for kind, t in rep["speeds"]["types"].items():
    print("shipped test check", kind, "samples median", round(t["samples"]["median"], 3), "old corpus IQR",
          round(t["corpus_train"]["q1"], 2), round(t["corpus_train"]["q3"], 2))
