"""Weight-space interpolation of two models with the same architecture and backbone:
python soup.py A B T OUT  ->  OUT = (1 - T) * A + T * B (every tensor; backbone tensors must be equal), config.json,
sampling.json and provenance.json copied from B (those B has)."""
import shutil
import sys
from pathlib import Path

import torch
from safetensors.torch import load_file, save_file

a, b, t, out = Path(sys.argv[1]), Path(sys.argv[2]), float(sys.argv[3]), Path(sys.argv[4])
wa, wb = load_file(a / "model.safetensors"), load_file(b / "model.safetensors")
assert wa.keys() == wb.keys(), "different tensors"
mixed, differ = {}, []
for k in wa:
    if torch.equal(wa[k], wb[k]):
        mixed[k] = wa[k]
    else:
        differ.append(k)
        mixed[k] = ((1 - t) * wa[k].float() + t * wb[k].float()).to(wa[k].dtype)
assert not any(k.startswith("backbone.") for k in differ), f"backbones differ: {[k for k in differ if k.startswith('backbone.')][:3]}"
tmp = out.with_name(out.name + ".tmp")
shutil.rmtree(tmp, ignore_errors=True)
tmp.mkdir(parents=True)
save_file(mixed, str(tmp / "model.safetensors"))
for name in ("config.json", "sampling.json", "provenance.json"):
    if (b / name).exists():
        shutil.copyfile(b / name, tmp / name)
shutil.rmtree(out, ignore_errors=True)
tmp.rename(out)
print(f"{out}: {len(differ)} of {len(wa)} tensors mixed at t {t}; e.g. {differ[:3]}")
