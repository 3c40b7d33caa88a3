#!/usr/bin/env bash
# Rule 87 (rule87.txt): X86 through C'' (against the simulator's low-g val replays), B' (Earth, val seeds 2 3), C+ and T,
# each only after the one before passed; verdict lines in rule87_stages.txt. Re-running skips every draw on disk.
# Needs /work/scratch/s74/val_g16 (the replays, val_g16.sh) and /work/scratch/s73/models/X86_model.
set -u
cd /work/main; . .venv/bin/activate
R=reports/training/s74_sim_reference; V=reports/training/s66_reference; S=/work/scratch/s39; OUT=$R/rule87_stages.txt
M=/work/scratch/s73/models/X86_model; REF=/work/scratch/s74/ref
export STEPS=50 W=2.5 ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 AA=0 EDIT_T=900 ETA=1 BALLISTIC= FB=
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
guard() {  # $1 phi, $2 seeds, $3 folder, $4 scratch (corpus3/ and eval/)
  [ -f $3/$1/check.json ] || SIMDIFF_SCRATCH=$4 SEEDS="$2" /usr/bin/time -f "stage $3 %e s" \
    python reports/training/s37_env_guidance/guard.py $1 1 $3/$1 $M >&2 || exit 1
}
stage_Cpp() {
  [ -f $REF/corpus3/val.txt ] || python $R/sim_reference.py $S/corpus3 /work/scratch/s74/val_g16 $S/eval $REF | tee -a $OUT
  guard -1.6,0,0 "3 4" $S/eval11/Cpp_X86 $REF
  { echo -n "C'' g -1.6 seeds 3 4 vs the simulator's val replays: "; python $V/v73.py text $S/eval11/Cpp_X86/-1.6,0,0; } \
    | tee -a $OUT | grep -q PASS
}
stage_B() {
  B=$S/eval11/B_X86_s23
  [ -f $B/check.json ] || BSEEDS="2 3" bash reports/training/s39_drift_gpu/check.sh B X86_s23 $M 1
  W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee /work/scratch/s74/walk87.txt \
    | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
  { echo -n "B' Earth seeds 2 3: "; python $R/v87.py $B "$W"; } | tee -a $OUT | grep -q PASS
}
stage_Cplus() {
  guard -9.81,10,0 "0" $S/eval11/Cp_X86 $S
  { echo -n "C+ w_x +10 N seed 0: "; python $V/v73.py text $S/eval11/Cp_X86/-9.81,10,0; } | tee -a $OUT | grep -q PASS
}
stage_T() {
  T=$S/eval11/T_X86
  [ -f $T/check.json ] || bash reports/training/s39_drift_gpu/check.sh T X86 $M 1
  { echo -n "T test seeds 0-4: "; python $V/v73.py test $T; } | tee -a $OUT
}
for st in ${STAGES:-Cpp B Cplus T}; do
  stamp "$st"; "stage_$st" || { echo "rule 87: $st failed" | tee -a $OUT; exit 0; }
done
stamp done
