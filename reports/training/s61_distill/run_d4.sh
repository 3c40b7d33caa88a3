# D4: X15sa's Earth and wind, the gravity answer of J40m_sa (another backbone, transplanted at the same x_t), from
# X15sa, 300 steps, λ 10, μ 20, α 0.5 / 1; then the probe with the low-gravity screen. GAIN=k NAME=... for k.
# D5: NAME=D5 INIT=/work/scratch/s61/D4_model FT=/work/scratch/s59/X15sg_model (X15sg's answer where the Earth motion flies);
# D6: the same with NAME=D6 MINF=0.2 (flights of >= 0.2 s only).
X=/work/scratch/s57/X15sa_model
NAME=${NAME:-D4} INIT=${INIT:-$X} G=${GT:-/work/scratch/s55/J40m_sa_model} E=$X W=$X STEPS=${STEPS:-300} PAIRS=10 DRIFT=20 \
  ALPHAS="0.5 1.0" MOON=16 bash "$(dirname "$0")/run_distill.sh"
