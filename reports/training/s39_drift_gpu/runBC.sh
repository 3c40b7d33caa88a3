bash check.sh B shipped /work/main/simdiff/assets/default_model
bash check.sh B ws_d20 /work/scratch/s39/gpu/ws_d20/model
bash stageC.sh shipped /work/main/simdiff/assets/default_model
bash stageC.sh ws_d20 /work/scratch/s39/gpu/ws_d20/model
echo ALLDONE
