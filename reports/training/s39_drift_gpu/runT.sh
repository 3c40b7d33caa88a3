bash check.sh T ws_d20 /work/scratch/s39/gpu/ws_d20/model
bash check.sh Tq shipped /work/scratch/s39/shipped_s29_model   # the session-29 weights, copied before shipping ws_d20
echo ALLDONE
