# Rule 28 (rule28.txt, committed before these ran): s_e 2 under the mask (baseline), then s_e 3 at g -1.6.
# (M50's training, run.sh, was paused with SIGSTOP while these ran: one job at a time on 2 cores.)
cd /work/main; . .venv/bin/activate
export SIMDIFF_SCRATCH=/work/scratch/s39 W=2.5 STEPS=50
M=simdiff/assets/default_model; C=/work/scratch/s39/eval11
for phi in -1.6,0,0 -9.81,10,0; do
  /usr/bin/time -f "stageC J40m se2 $phi %e s" python reports/training/s37_env_guidance/guard.py $phi 2 $C/C_J40m_se2/$phi $M
done
/usr/bin/time -f "stageC J40m se3 -1.6 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 3 $C/C_J40m_se3/-1.6,0,0 $M
# s_e 3 passed (c) at g -1.6; then stage A (response) and stage C at +10 N
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_se3 $M 3
/usr/bin/time -f "stageC J40m se3 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 3 $C/C_J40m_se3/-9.81,10,0 $M
# s_e 3 passed (a)-(c): sampling.json "env_guidance": 3.0; the test split once, three evaluators
S=/work/scratch/s39
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se3 $M 3
# rule 29 (rule29.txt, written after the s_e 3 test run): s_e 4 — stage C at g -1.6, A, C at +10 N, all passed;
# sampling.json "env_guidance": 4.0 and the test split once more
/usr/bin/time -f "stageC J40m se4 -1.6 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 $C/C_J40m_se4/-1.6,0,0 $M
STEPS=50 bash reports/training/s39_drift_gpu/check.sh A J40m_se4 $M 4
/usr/bin/time -f "stageC J40m se4 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 $C/C_J40m_se4/-9.81,10,0 $M
STEPS=50 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T 3_J40m_se4 $M 4   # 1,669 s
python benchmarks/bench_generate.py --json reports/training/s50_anneal/bench_generate.json
