"""How far the Sim Encoder moves e_sim from Earth for each probe φ: python sim_embed.py MODEL...
Prints ||e(φ) - e(Earth)|| and the cosine between the +/- wind embeddings' displacements (per model)."""
import sys

import torch
from safetensors.torch import load_file

PHI = {"wx+10": (-9.81, 10, 0), "wx-10": (-9.81, -10, 0), "wy+10": (-9.81, 0, 10), "wy-10": (-9.81, 0, -10),
       "g-1.6": (-1.6, 0, 0)}
for m in sys.argv[1:]:
    w = load_file(f"{m}/model.safetensors")
    def e(phi):
        x = torch.tensor([[(phi[0] + 9.81) / 9.81, phi[1] / 10, phi[2] / 10]])
        h = torch.nn.functional.silu(x @ w["sim_encoder.embed.weight"].T + w["sim_encoder.embed.bias"])
        return h @ w["sim_encoder.proj.weight"].T + w["sim_encoder.proj.bias"]
    e0 = e((-9.81, 0, 0))
    d = {k: (e(v) - e0)[0] for k, v in PHI.items()}
    cos = lambda a, b: float(torch.nn.functional.cosine_similarity(a, b, dim=0))
    print(m.split("/")[-1].ljust(14), " ".join(f"{k} {float(v.norm()):.3f}" for k, v in d.items()),
          f"| cos(wx+,wx-) {cos(d['wx+10'], d['wx-10']):+.2f} cos(wy+,wy-) {cos(d['wy+10'], d['wy-10']):+.2f}",
          f"cos(wx+,g) {cos(d['wx+10'], d['g-1.6']):+.2f} cos(wy-,g) {cos(d['wy-10'], d['g-1.6']):+.2f}")
