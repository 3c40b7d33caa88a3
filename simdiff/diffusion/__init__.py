"""Gaussian diffusion for x₀-predicting motion models: schedule, DDPM, DDIM, guidance, loss, sampling loop,
and the sampling configuration (:mod:`simdiff.diffusion.config`, importable without torch)."""
