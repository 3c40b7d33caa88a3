#!/usr/bin/env bash
# Rule 87 (rule87.txt): X86 through C'' (against the simulator's low-g val replays), B' (Earth, val seeds 2 3), C+ and T,
# each only after the one before passed; verdict lines in rule87_stages.txt. Re-running skips every draw on disk.
# Needs /work/scratch/s74/val_g16 (the replays, val_g16.sh) and /work/scratch/s73/models/X86_model.
# Rule 88 (run88.sh) runs the same with RULE=88 N=X88 M=<its folder> CPP_SEEDS="5 6" AS=162 and the gate and stage A
# first (STAGES="gate A Cpp B Cplus T"); B' seeds stay 2 3 (at Earth X88 samples what X86 samples).
# Session 76: GUIDANCE (default 2.5), B_SEEDS, B_VERDICT and T_VERDICT (rule 93); the walk guard count is WG (it was W,
# which then set the guidance of C+ and T to the count: no rule had reached C+ or T through this script).
# Session 80: SE (environment guidance, default 1) and EDIT_T (default 900) from the environment (rule 98).
set -u
cd /work/main; . .venv/bin/activate
RULE=${RULE:-87} N=${N:-X86} M=${M:-/work/scratch/s73/models/X86_model} CPP_SEEDS=${CPP_SEEDS:-3 4} AS=${AS:-160}
R=reports/training/s74_sim_reference; V=reports/training/s66_reference; S=/work/scratch/s39; OUT=${STAGES_OUT:-$R/rule${RULE}_stages.txt}
REF=/work/scratch/s74/ref
export STEPS=50 W=${GUIDANCE:-2.5} ALPHA=0.925 ANCHOR=edit ANCHOR_ALPHA=0 AA=0 EDIT_T=${EDIT_T:-900} ETA=1 BALLISTIC= FB=
SE=${SE:-1}  # environment guidance s_e of every stage (session 80, rule 98; it was always 1)
export PROBE_ANCHOR=edit PROBE_ANCHOR_ALPHA=0  # the walk guard as run73.sh ran it for rule 86
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
guard() {  # $1 phi, $2 seeds, $3 folder, $4 scratch (corpus3/ and eval/)
  [ -f $3/$1/check.json ] || SIMDIFF_SCRATCH=$4 SEEDS="$2" /usr/bin/time -f "stage $3 %e s" \
    python reports/training/s37_env_guidance/guard.py $1 $SE $3/$1 $M >&2 || exit 1
}
stage_gate() {  # rule 84's gate (env_probe seeds 7000+, gate84.py with speed bar 0.209)
  PROBE=/work/scratch/s74/${N}_probe.log; mkdir -p /work/scratch/s74  # session 81: a fresh scratch has no s74/
  grep -qs "^{" $PROBE || python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 $M > $PROBE 2>&1
  python reports/training/s72_lowloc/gate84.py "$PROBE" $RULE 0.209 | tee -a $OUT | grep -q "gate PASS"
}
stage_A() {  # seeds AS AS+1, 32 samples per jump prompt
  A=$S/eval11/A_${N}_s$AS
  [ -f $A/check.json ] || JS=32 ASEEDS="$AS $((AS + 1))" bash reports/training/s39_drift_gpu/check.sh A ${N}_s$AS $M $SE
  python reports/training/s57_pooled_a/stage_a55.py $A | tee -a $OUT | grep -q PASS
}
stage_Cpp() {
  [ -f $REF/corpus3/val.txt ] || python $R/sim_reference.py $S/corpus3 /work/scratch/s74/val_g16 $S/eval $REF | tee -a $OUT
  guard -1.6,0,0 "$CPP_SEEDS" $S/eval11/Cpp_$N $REF
  { echo -n "C'' g -1.6 seeds $CPP_SEEDS vs the simulator's val replays: "; python $V/v73.py text $S/eval11/Cpp_$N/-1.6,0,0; } \
    | tee -a $OUT | grep -q PASS
}
stage_B() {  # B_SEEDS (default "2 3"); B_VERDICT (default v87.py) takes the report folder and the walk guard count
  local bs=${B_SEEDS:-2 3}; B=$S/eval11/B_${N}_s${bs// /}
  [ -f $B/check.json ] || BSEEDS="$bs" bash reports/training/s39_drift_gpu/check.sh B ${N}_s${bs// /} $M $SE
  WG=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee /work/scratch/s74/walk$RULE.txt \
    | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')  # WG, not W: W is the guidance the stages after this one use
  { echo -n "B' Earth seeds $bs: "; ${B_VERDICT:-python $R/v87.py} $B "$WG"; } | tee -a $OUT | grep -q PASS
}
stage_Cplus() {
  guard -9.81,10,0 "0" $S/eval11/Cp_$N $S
  { echo -n "C+ w_x +10 N seed 0: "; python $V/v73.py text $S/eval11/Cp_$N/-9.81,10,0; } | tee -a $OUT | grep -q PASS
}
stage_T() {
  T=$S/eval11/T_$N
  [ -f $T/check.json ] || bash reports/training/s39_drift_gpu/check.sh T $N $M $SE
  { echo -n "T test seeds 0-4: "; ${T_VERDICT:-python $V/v73.py test} $T; } | tee -a $OUT
}
for st in ${STAGES:-Cpp B Cplus T}; do
  stamp "$st"; "stage_$st" || { echo "rule $RULE: $st failed" | tee -a $OUT; exit 0; }
done
stamp done
