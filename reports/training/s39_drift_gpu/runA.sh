bash check.sh A shipped /work/main/simdiff/assets/default_model
for n in ws_d0 ws_d20 ws_d50 ws_d100; do bash check.sh A $n /work/scratch/s39/gpu/$n/model; done
echo ALLDONE
