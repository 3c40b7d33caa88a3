# Rule 54 (session 56): J40m_sa300 = rule 50's recipe for 300 steps; stages A, C', C+, B.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s56; R=reports/training/s56_source_anchored; M=$O/J40m_sa300_model
export SIMDIFF_SCRATCH=$S STEPS=50
/usr/bin/time -f "train J40m_sa300 %e s" python -m simdiff train adapters --targets source-anchored \
  --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init simdiff/assets/default_model --adapters-init simdiff/assets/default_model --out $O/ad54 \
  --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 55 --batch-size 64 \
  --save-every 100 --device cpu --steps 300 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
  || { echo "training failed"; exit 1; }
rm -rf $M; cp -r $O/ad54/model $M; cp simdiff/assets/default_model/sampling.json $M/
FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_sa300_se4_fb3 $M 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_sa300_se4_fb3 || { echo "rule 54: A failed"; exit 1; }
SEEDS="1 2" /usr/bin/time -f "stageC12 J40m_sa300_se4 %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 4 \
  $S/eval11/C12_J40m_sa300_se4/-1.6,0,0 $M || exit 1
python $R/c51.py C12 J40m_sa300_se4 || { echo "rule 54: C' failed"; exit 1; }
/usr/bin/time -f "stageC J40m_sa300_se4 +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 4 \
  $S/eval11/C_J40m_sa300_se4/-9.81,10,0 $M || exit 1
python $R/c51.py CPLUS J40m_sa300_se4 || { echo "rule 54: C+ failed"; exit 1; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_sa300 $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M 2>&1 | tee -a $O/walk54.txt | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
echo "walk guard: $W of 64"
python reports/training/s55_reference/stage_b49.py J40m_sa300 $W && echo "rule 54: A, C', C+ and B passed" || echo "rule 54: B failed"
