# Rule 73 (session 66; rule73.txt): G63r (G63's weights, reference anchor at anchor_alpha 0, s_e 3, fallback 2) through
# the gate, C', A, B, C+ and T, each only after the one before passed. Verdict lines go to rule73_stages.txt.
# Re-running skips every draw already on disk (the check folders under /work/scratch/s39/eval11).
# Rule 74 (rule74.txt) runs the same with RULE=74 N=G63r5 SE=5 FB=4 AS=142 (run74.sh).
# Session 67: MODELS (folder holding ${N}_model, default /work/scratch/s66), R (where the verdict lines go, default
# this folder) and STAGES (their order, default "gate C' A B C+ T") for later rules; the defaults are rule 73's run.
# BALLISTIC (the model's ballistic strength, default off) goes to every draw; BDRAW: stage B's draw (see stage_B).
# Session 70: ANC (the anchor, default reference), ALPHA (default 0.5), EDIT_T (the edit anchor's edit t) and ETA (DDIM
# eta) for rules 81-82; FB empty: no fallback. Session 72: GATE (the gate's verdict script, default gate68.py) and
# GATE_ARGS (its arguments after the probe log and the rule) for rule 84.
set -u
RULE=${RULE:-73} N=${N:-G63r} SE=${SE:-3} FB=${FB-2} AS=${AS:-140}
cd /work/main; . .venv/bin/activate
V=reports/training/s66_reference; R=${R:-$V}; S=/work/scratch/s39; MODELS=${MODELS:-/work/scratch/s66}; M=$MODELS/${N}_model
OUT=$R/rule${RULE}_stages.txt; R57=reports/training/s57_pooled_a
export BALLISTIC=${BALLISTIC:-} SIMDIFF_SCRATCH=$S STEPS=50 ANCHOR=${ANC:-reference} AA=0 ANCHOR_ALPHA=0 PROBE_ANCHOR=${ANC:-reference} PROBE_ANCHOR_ALPHA=0
export ALPHA=${ALPHA:-0.5} EDIT_T=${EDIT_T:-} ETA=${ETA:-}
stamp() { echo "[$(date -u +%H:%M)] $*" >&2; }
guard() {  # $1 phi, $2 seeds, $3 folder
  [ -f $3/$1/check.json ] || SEEDS="$2" /usr/bin/time -f "stage $3 %e s" python reports/training/s37_env_guidance/guard.py \
    $1 $SE $3/$1 $M >&2 || exit 1
}
stage_gate() {
  PROBE=$MODELS/${N}_probe.log
  [ -s $PROBE ] || python reports/training/s60_wind/env_probe.py --walks 8 --jumps 8 --moon 16 $M > $PROBE 2>&1
  python ${GATE:-reports/training/s61_distill/gate68.py} "$PROBE" $RULE ${GATE_ARGS:-} | tee -a $OUT | grep -q "gate PASS"
}
stage_Cp() {  # C'
  guard -1.6,0,0 "1 2" $S/eval11/C12_$N
  { echo -n "C' g -1.6 seeds 1 2: "; python $V/v73.py text $S/eval11/C12_$N/-1.6,0,0; } | tee -a $OUT | grep -q PASS
}
stage_A() {
  A=$S/eval11/A_${N}_s$AS
  [ -f $A/check.json ] || JS=32 ASEEDS="$AS $((AS + 1))" FB=$FB bash reports/training/s39_drift_gpu/check.sh A ${N}_s$AS $M $SE
  python $R57/stage_a55.py $A | tee -a $OUT | grep -q PASS
}
stage_B() {  # BDRAW: session 65's Earth draw unless given (drawn here when missing: BDRAW=$S/eval11/B_$N)
  B=${BDRAW:-$S/eval11/B_G63a0_s65}
  [ -f $B/check.json ] || bash reports/training/s39_drift_gpu/check.sh B ${B##*/B_} $M $SE
  W=$(cd reports/training/s53_extrapolate && python walk_probe.py $M | tee $MODELS/walk$RULE.txt \
    | sed -n 's/.*jumping \([0-9]*\)\/.*/\1/p')
  { echo -n "B Earth seeds 0 1 (${B##*/}): "; python $V/v73.py earth $B "$W"; } | tee -a $OUT | grep -q PASS
}
stage_C+() {
  guard -9.81,10,0 "0" $S/eval11/Cp_$N
  { echo -n "C+ w_x +10 N seed 0: "; python $V/v73.py text $S/eval11/Cp_$N/-9.81,10,0; } | tee -a $OUT | grep -q PASS
}
stage_T() {
  T=$S/eval11/T_${N}_se${SE}_fb$FB
  [ -f $T/check.json ] || FB=$FB bash reports/training/s39_drift_gpu/check.sh T ${N}_se${SE}_fb$FB $M $SE
  { echo -n "T test seeds 0-4: "; python $V/v73.py test $T; } | tee -a $OUT
}
for st in ${STAGES:-gate C\' A B C+ T}; do
  stamp "$st"; "stage_${st//\'/p}" || { echo "rule $RULE: $st failed"; exit 0; }
done
stamp done
