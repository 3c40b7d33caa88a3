"""Session 48: paired (per-seed) differences, anchor w 3.0 minus shipped, on the test split under evaluators 1 and 3
(the two T3_* runs of run.sh; Student-t 95 % over the 5 seeds). Usage: python paired.py"""
import json
from simdiff.eval.stats import t_interval
S='/work/scratch/s39/eval11/'
a=json.load(open(S+'T3_J40anchor_w3.0/check.json'))['test_split']
b=json.load(open(S+'T3_J40w2.5s50/check.json'))['test_split']
def per(ts, which):
    if which==0: return ts['per_seed']['generated']
    return ts['more_evaluators'][which-1]['per_seed']['generated']
# shipped: eval1=0, eval2=1, eval3=2 ; anchor: eval1=0, eval3=1
for name, ia, ib in (('eval1',0,0),('eval3',1,2)):
    for k in ('fid','r_precision_top3'):
        xa=[r[k] for r in per(a,ia)]; xb=[r[k] for r in per(b,ib)]
        d=[x-y for x,y in zip(xa,xb)]; m,h=t_interval(d)
        print(name,k,'anchor %.3f shipped %.3f diff %+.3f ± %.3f'%(sum(xa)/5,sum(xb)/5,m,h))
