"""Session 69 screen: environment guidance boosted at the earliest, noisiest steps only (no package change: the
guidance object's s_e is swapped per call). python early_screen.py MODEL --t-early T --se-early S [ballistic_screen args]
Steps with timestep > T use s_e = S, the rest the model's own s_e (sampling.json). Why: fit_probe.py found the
adapters' answer to gravity only where x_t no longer shows the jump (t >= 950); below it x̂₀ follows x_t's height."""
import runpy
import sys
from pathlib import Path

import simdiff.diffusion.guidance as guidance

argv = sys.argv[1:]
i = argv.index("--t-early"); T = int(argv[i + 1]); del argv[i:i + 2]
i = argv.index("--se-early"); S = float(argv[i + 1]); del argv[i:i + 2]
cls = guidance.GuidedDenoiser
_call = cls.__call__


def boosted(self, x, timesteps, cond):
    if int(timesteps.max()) <= T or self.env_scale == 1.0:
        return _call(self, x, timesteps, cond)
    keep, self.env_scale = self.env_scale, S
    try:
        return _call(self, x, timesteps, cond)
    finally:
        self.env_scale = keep


cls.__call__ = boosted
sys.argv = ["ballistic_screen.py"] + argv
screen = Path(__file__).resolve().parent.parent / "s67_ballistic" / "ballistic_screen.py"
sys.path.insert(0, str(screen.parent))
runpy.run_path(str(screen), run_name="__main__")
