# Rules 42-43 choice after X15a_a25's stage A: X15a_a25 at the s_e that passed, else X15a at s_e 5 (fallback 3).
set -u
cd /work/main
S=/work/scratch/s39; M=/work/scratch/s54/X15a_model
while pgrep -f "run43A.sh" > /dev/null; do sleep 10; done
for p in 8:6 10:7.5 12:9; do
  se=${p%%:*}; fb=${p#*:}
  if [ -f $S/eval11/A_X15a_a25_se${se}_fb${fb}/check.json ] && \
     .venv/bin/python reports/training/s54_refit/stage_a_pass.py $S/eval11/A_X15a_a25_se${se}_fb${fb}; then
    echo "chosen X15a_a25 s_e $se fallback $fb"; exec bash reports/training/s54_refit/runCT.sh X15a_a25_se${se}_fb${fb} $M $se $fb 0.25
  fi
done
echo "chosen X15a s_e 5 fallback 3"; exec bash reports/training/s54_refit/runCT.sh X15a_se5_fb3 $M 5 3 0.5
