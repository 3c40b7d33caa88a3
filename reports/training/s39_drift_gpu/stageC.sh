# usage: stageC.sh NAME MODEL [S_E] (S_E: environment guidance, default 2; session 42; env W, STEPS: guidance and DDIM steps, default 2.5, 20; session 46; env ANCHOR: guidance anchor, default adapters; session 47; env ALPHA: adapter strength, default 0.5; session 54)
cd /work/main; . .venv/bin/activate
export SIMDIFF_SCRATCH=/work/scratch/s39
for phi in -1.6,0,0 -9.81,10,0; do
/usr/bin/time -f "stageC $1 $phi %e s" python reports/training/s37_env_guidance/guard.py $phi ${3:-2} /work/scratch/s39/eval11/C_$1/$phi $2
done
