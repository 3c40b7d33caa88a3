#!/usr/bin/env bash
# The shipped model's (J40m's) test check again, with today's model check (length-matched walk and run speeds) and
# evaluator 1 as rebuilt in session 65, so later candidates' stage T can be compared with it in one evaluator run.
# Same settings as its report reports/training/s53_extrapolate/test/J40m_se4_fb3 (DDIM 50, guidance 2.5, alpha 0.5,
# foot lock 1, adapters anchor, s_e 4, fallback 3; test n 256 x seeds 0-4, response on), without evaluators 2 and 3.
cd /work/main
STEPS=50 FB=3 bash reports/training/s39_drift_gpu/check.sh T J40m_s68 simdiff/assets/default_model 4
