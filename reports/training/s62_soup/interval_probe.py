"""Guidance in a limited interval (session 62 screen): classifier-free guidance only at timesteps t <= T_HI (and >= T_LO),
the conditional network alone at the others (Kynkäänniemi et al. 2024: guidance at the noisiest steps pulls samples
towards a few typical ones). `patch(t_hi, t_lo)` switches every GuidedDenoiser in this process; interval_wrap.py runs a
script under it, e.g. the jump probe of session 53 (6 prompts x 8, seeds 1000+i, the shipped settings):
cd reports/training/s53_extrapolate && T_HI=600 python ../s62_soup/interval_wrap.py ag_probe.py MODEL MODEL '[{"lam": 0}]' 8"""
from __future__ import annotations

from simdiff.diffusion import guidance as G

_plain = G.GuidedDenoiser._text_guided


def patch(t_hi: int, t_lo: int = 0) -> None:
    def text_guided(self, x, timesteps, cond):
        t = int(timesteps.max())
        if t > t_hi or t < t_lo:
            out = self.denoiser(x, timesteps, cond)
            return out, out
        return _plain(self, x, timesteps, cond)
    G.GuidedDenoiser._text_guided = text_guided
