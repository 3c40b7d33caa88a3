# Rule 50 (session 55): the shipped adapters fine-tuned with source-anchored targets (J40m_sa); stages C, B, A on val.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s55; R=reports/training/s55_reference; M=$O/J40m_sa_model
mkdir -p $O
while pgrep -f aug_rebuild.sh > /dev/null; do sleep 10; done
/usr/bin/time -f "train J40m_sa %e s" env SOURCE_ANCHORED=$S/corpus3 python $R/source_anchored.py -m simdiff train adapters \
  --data $S/aug_weakg $S/aug_gen $S/aug_wind --split first_try \
  --init simdiff/assets/default_model --adapters-init simdiff/assets/default_model --out $O/ad50 \
  --config configs/adapters_paired_gpu_finetune.json --env-pairs 10 --env-pairs-drift 20 --seed 55 --batch-size 64 \
  --save-every 100 --device cpu --steps 1000 --text-table .gpu/captions.safetensors --loader-workers 1 --no-progress \
  || { echo "training failed"; exit 1; }
rm -rf $M; cp -r $O/ad50/model $M; cp simdiff/assets/default_model/sampling.json $M/
export SIMDIFF_SCRATCH=$S STEPS=50
for phi in -1.6,0,0 -9.81,10,0; do
  /usr/bin/time -f "stageC J40m_sa_se4 $phi %e s" python reports/training/s37_env_guidance/guard.py $phi 4 \
    $S/eval11/C_J40m_sa_se4/$phi $M
  [ "$phi" = -1.6,0,0 ] && { python - <<PY || { echo "stage C failed at g -1.6: no more"; exit 1; }
import json; g = json.load(open("$S/eval11/C_J40m_sa_se4/-1.6,0,0/check.json"))["test_split"]["generated"]
print(f"J40m_sa_se4 phi -1.6,0,0: R@3 {g['r_precision_top3']['mean']:.3f} (bar 0.782), FID {g['fid']['mean']:.2f} (bar 2.91)")
raise SystemExit(0 if g["r_precision_top3"]["mean"] >= 0.812 - 0.03 and g["fid"]["mean"] <= 1.25 * 2.33 else 1)
PY
  }
done
python $R/stage_c48.py J40m_sa_se4 || { echo "stage C failed: no B, A"; exit 1; }
ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh B J40m_sa $M 4
W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee /dev/stderr | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
python $R/stage_b49.py J40m_sa $W || { echo "stage B failed: no A"; exit 1; }
FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_sa_se4_fb3 $M 4
python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_sa_se4_fb3 || { echo "stage A failed"; exit 1; }
echo "rule 50: C, B and A passed; stage T is the next session's"
