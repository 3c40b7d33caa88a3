# Rule 51 (session 56): J40m_sa (rule 50's weights) at stages C' (g -1.6, val seeds 1 2, with the shipped base), C+, B,
# A, T; then the matched control (plain targets, same recipe) and its stage B. Each stage only after the one before passed.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s55; R=reports/training/s56_source_anchored; M=$O/J40m_sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
[ -f $M/model.safetensors ] || python reports/training/s55_reference/make_model.py $M || exit 1
control() {
  /usr/bin/time -f "train J40m_ctl %e s" python -m simdiff train adapters \
    --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
    --init simdiff/assets/default_model --adapters-init simdiff/assets/default_model --out $O/ad51c \
    --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 55 --batch-size 64 \
    --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
    || { echo "control training failed"; exit 1; }
  rm -rf $O/J40m_ctl_model; cp -r $O/ad51c/model $O/J40m_ctl_model; cp simdiff/assets/default_model/sampling.json $O/J40m_ctl_model/
  ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_ctl $O/J40m_ctl_model 4
  (cd reports/training/s53_extrapolate && python stage_b.py J40m_c3 J40m_sa J40m_ctl)
  exit 0
}
for pair in J40m_se4:simdiff/assets/default_model J40m_sa_se4:$M; do
  n=${pair%%:*}; m=${pair#*:}
  SEEDS="1 2" /usr/bin/time -f "stageC12 $n %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
    $S/eval11/C12_$n/-1.6,0,0 $m || exit 1
done
python $R/c51.py C12 || { echo "rule 51: C' failed"; control; }
/usr/bin/time -f "stageC J40m_sa_se4 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_J40m_sa_se4/-9.81,10,0 $M || exit 1
python $R/c51.py CPLUS || { echo "rule 51: C+ failed"; control; }
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee /dev/stderr | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python reports/training/s55_reference/stage_b49.py J40m_sa $W || { echo "rule 51: B failed"; control; }
FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_sa_se4_fb3 $M 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_sa_se4_fb3 || { echo "rule 51: A failed"; control; }
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T J40m_sa_se4_fb3 $M 4
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_J40m_sa_se4_fb3 T_3_J40m_se4_fb3_c53
python $R/t51.py T_J40m_sa_se4_fb3 && echo "rule 51: SHIP" || echo "rule 51: T failed, not shipped"
control
