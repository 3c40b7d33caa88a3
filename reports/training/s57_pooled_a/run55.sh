# Rule 55 (session 57): J40m_sa at stage A'' (val seeds 104-107), then stage T if it passed; then the shipped model on
# stage A'' 's seeds (described). Each judged stage only after the one before passed.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s55; R=reports/training/s57_pooled_a; M=$O/J40m_sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
[ -f $M/model.safetensors ] || python reports/training/s55_reference/make_model.py $M || exit 1
base() {
  ASEEDS="104 105 106 107" FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_se4_fb3_s104 simdiff/assets/default_model 4
  python $R/stage_a55.py $S/eval11/A_J40m_se4_fb3_s104 >> $R/stageA_summary.txt
}
ASEEDS="104 105 106 107" FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_sa_se4_fb3_s104 $M 4
python $R/stage_a55.py $S/eval11/A_J40m_sa_se4_fb3_s104 | tee -a $R/stageA_summary.txt | grep -q PASS \
  || { echo "rule 55: A'' failed"; base; exit 0; }
echo "rule 55: A'' passed"
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T J40m_sa_se4_fb3 $M 4
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_J40m_sa_se4_fb3 T_3_J40m_se4_fb3_c53 | tee -a $R/stageT_summary.txt
python reports/training/s56_source_anchored/t51.py T_J40m_sa_se4_fb3 | tee -a $R/stageT_summary.txt
[ ${PIPESTATUS[0]} -eq 0 ] && echo "rule 55: SHIP" || echo "rule 55: T failed, not shipped"
base
