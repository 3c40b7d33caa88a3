# Rule 52 (session 56): J40m_sa at env guidance 6 (then 8): stage A choice, then C', C+, T.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; R=reports/training/s56_source_anchored; M=/work/scratch/s55/J40m_sa_model
export SIMDIFF_SCRATCH=$S STEPS=50
while pgrep -f run51.sh > /dev/null; do sleep 15; done
SE=
for se in 6 8; do
  FB=3 bash reports/training/s39_drift_gpu/check.sh A J40m_sa_se${se}_fb3 $M $se
  python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_J40m_sa_se${se}_fb3 && { SE=$se; break; }
done
[ -n "$SE" ] || { echo "rule 52: no s_e passed stage A"; exit 1; }
echo "rule 52: chose s_e $SE"
SEEDS="1 2" /usr/bin/time -f "stageC12 J40m_sa_se$SE %e s" python reports/training/s37_env_guidance/guard.py -1.6,0,0 $SE \
  $S/eval11/C12_J40m_sa_se$SE/-1.6,0,0 $M || exit 1
python $R/c51.py C12 J40m_sa_se$SE || { echo "rule 52: C' failed"; exit 1; }
/usr/bin/time -f "stageC J40m_sa_se$SE +10N %e s" python reports/training/s37_env_guidance/guard.py -9.81,10,0 $SE \
  $S/eval11/C_J40m_sa_se$SE/-9.81,10,0 $M || exit 1
python $R/c51.py CPLUS J40m_sa_se$SE || { echo "rule 52: C+ failed"; exit 1; }
FB=3 ALSO="$S/eval2 --also-evaluator $S/eval3" bash reports/training/s39_drift_gpu/check.sh T J40m_sa_se${SE}_fb3 $M $SE
mkdir -p $S/eval11/T_3_J40m_se4_fb3_c53
cp reports/training/s53_extrapolate/test/J40m_se4_fb3/check.json $S/eval11/T_3_J40m_se4_fb3_c53/
python reports/training/s52_runs_lowg/test_summary.py T_J40m_sa_se${SE}_fb3 T_3_J40m_se4_fb3_c53
python $R/t51.py T_J40m_sa_se${SE}_fb3 && echo "rule 52: SHIP s_e $SE" || echo "rule 52: T failed, not shipped"
