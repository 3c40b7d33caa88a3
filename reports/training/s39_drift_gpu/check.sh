# usage: check.sh STAGE NAME MODEL [S_E] — rule 11's model_check runs (scratch in /work/scratch/s39, out eval11/STAGE_NAME)
#   S_E: environment guidance (default 2; session 42); env W, STEPS: guidance and DDIM steps (default 2.5, 20; session 46);
#   env ALPHA: adapter strength (default 0.5; session 47); env ANCHOR: model_check --anchor (default adapters; session 47)
#   env ALSO: a second evaluator folder that scores the same test-split motions (--also-evaluator; session 48)
#   env PYWRAP: a script that runs benchmarks/model_check.py with a patch (session 51: s51_floor/floored.py)
#   env FB: --env-guidance-fallback (session 52)
#   env AA: --anchor-alpha (session 55)
#   env BALLISTIC: --ballistic (session 67)
#   env EDIT_T: --edit-t, with ANCHOR=edit (session 70); env ETA: --eta, DDIM eta (session 70)
#   env ASEEDS: stage A's seeds (default "100 101"; session 56); they split the 16 samples per jump prompt, so more seeds
#     do not raise n (96 jump pairs, 64 windy walks; session 57); env JS: samples per jump prompt (default 16; session 57)
#   env BSEEDS: stage B's seeds (default "0 1"; session 74)
#   A: selection seeds 100 101, val n 32, response on   B: val n 128 seeds 0 1, no response
#   T: test n 256 seeds 0-4, response on                 Tq: the same without the response
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39
case $1 in
  A) args="--split val --n 32 --seeds ${ASEEDS:-100 101} --workers 2";;
  B) args="--split val --n 128 --seeds ${BSEEDS:-0 1} --no-response";;
  T) args="--split test --n 256 --seeds 0 1 2 3 4 --workers 2";;
  Tq) args="--split test --n 256 --seeds 0 1 2 3 4 --no-response";;
  *) echo "check.sh: unknown stage '$1' (A, B, T or Tq)" >&2; exit 2;;
esac
/usr/bin/time -f "stage$1 $2 %e s" python ${PYWRAP} benchmarks/model_check.py --model $3 --corpus $S/corpus3 --evaluator $S/eval \
  $args --jump-samples ${JS:-16} --speed-samples 8 --steps ${STEPS:-20} --guidance ${W:-2.5} --alpha ${ALPHA:-0.5} --foot-lock 1 --env-guidance ${4:-2} --anchor ${ANCHOR:-adapters} ${AA:+--anchor-alpha $AA} ${FB:+--env-guidance-fallback $FB} ${BALLISTIC:+--ballistic $BALLISTIC} ${EDIT_T:+--edit-t $EDIT_T} ${ETA:+--eta $ETA} ${ALSO:+--also-evaluator $ALSO} --threads 2 \
  --out $S/eval11/${1:0:1}_$2 -q
