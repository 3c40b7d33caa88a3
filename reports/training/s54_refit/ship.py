"""Write the shipped model folder from rules 42-43's candidate: python ship.py SRC S_E FALLBACK ALPHA OUT
SRC: X15a's folder (X1.5's backbone + re-fitted adapters); EXTRAP: X1.5's folder (its extrapolation.json).
Copies weights and config, writes sampling.json with the chosen settings, the recipe and the provenance notes."""
import json
import shutil
import sys
from pathlib import Path

from simdiff.model.provenance import Provenance, read_provenance, write_provenance

EXTRAP = Path("/work/scratch/s53/wx1.5")
REFIT = ("session 54: the session-41 adapters warm-started on the extrapolated backbone (see the backbone entries) and "
         "re-fitted 1,000 steps of batch 64 on 2 CPU cores (16 min; lambda 10, mu 20, lr 1e-4, seed 53; same data "
         "and losses as session 41; reports/training/s54_refit/run42train.sh)")
EXTRAPOLATED = ("; session 54: this fine-tune extrapolated in weight space, backbone = theta41 + 1.5 (theta41 - "
                "theta25) (`simdiff train extrapolate --lam 1.5`, extrapolation.json; reports/training/s53_extrapolate/)")

src, se, fb, alpha, out = Path(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), Path(sys.argv[5])
for name in ("model.safetensors", "config.json"):
    shutil.copyfile(src / name, out / name)
sampling = json.loads((out / "sampling.json").read_text())
sampling.update(alpha=alpha, env_guidance=se, env_guidance_fallback=fb)
(out / "sampling.json").write_text(json.dumps(sampling, indent=2) + "\n")
recipe = json.loads((EXTRAP / "extrapolation.json").read_text())
recipe.update(model="simdiff/assets/default_model at 419edfc (session 41's backbone, J40m)",
              parent="simdiff/assets/default_model at 1c859a7 (session 25's backbone)",
              then="adapters re-fitted on the extrapolated backbone (session 54), so model.safetensors is not the "
                   "extrapolation's output; model_sha256 and parent_sha256 are the inputs'")
(out / "extrapolation.json").write_text(json.dumps(recipe, indent=2) + "\n")
prov = read_provenance(src)
parts = list(prov.trained_on)
for p in parts:
    if p.what == "adapters" and "session" not in p.note:
        p.note = (p.note + "; " if p.note else "") + REFIT
    if p.what == "backbone" and p.note.startswith("session 41"):
        p.note += EXTRAPOLATED
write_provenance(out, Provenance(parts))
print("wrote", out, sampling)
