"""How far the Sim Encoder moves e_sim from Earth for each probe φ: python sim_embed.py MODEL...
Prints ||e(φ) - e(Earth)|| and the cosines between the wind displacements and with gravity's (per model)."""
import sys

import torch
from torch.nn.functional import cosine_similarity

from simdiff.model.generator import MotionGenerator

EARTH = (-9.81, 0.0, 0.0)
PHI = {"wx+10": (-9.81, 10, 0), "wx-10": (-9.81, -10, 0), "wy+10": (-9.81, 0, 10), "wy-10": (-9.81, 0, -10),
       "g-1.6": (-1.6, 0, 0)}
for m in sys.argv[1:]:
    encoder = MotionGenerator.load(m).network.sim_encoder
    with torch.no_grad():
        e = encoder(torch.tensor([EARTH, *PHI.values()], dtype=torch.float32))
    d = dict(zip(PHI, e[1:] - e[0]))

    def cos(a: str, b: str) -> float:
        return float(cosine_similarity(d[a], d[b], dim=0))

    print(m.split("/")[-1].ljust(14), " ".join(f"{k} {float(v.norm()):.3f}" for k, v in d.items()),
          f"| cos(wx+,wx-) {cos('wx+10', 'wx-10'):+.2f} cos(wy+,wy-) {cos('wy+10', 'wy-10'):+.2f}",
          f"cos(wx+,g) {cos('wx+10', 'g-1.6'):+.2f} cos(wy-,g) {cos('wy-10', 'g-1.6'):+.2f}")
