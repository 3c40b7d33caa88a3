"""Write a model folder whose backbone weights are good + lam*(good - parent) (adapters, normaliser: good's).
Usage: python extrap_weights.py GOOD PARENT LAM OUT"""
import shutil, sys
from pathlib import Path
from safetensors.torch import load_file, save_file
good, parent, lam, out = sys.argv[1], sys.argv[2], float(sys.argv[3]), Path(sys.argv[4])
g, p = load_file(f"{good}/model.safetensors"), load_file(f"{parent}/model.safetensors")
w = {k: (v + lam * (v - p[k]) if k.startswith("backbone.") and v.is_floating_point() else v).contiguous() for k, v in g.items()}
out.mkdir(parents=True, exist_ok=True)
for f in Path(good).iterdir():
    if f.name != "model.safetensors":
        shutil.copy(f, out / f.name)
save_file(w, str(out / "model.safetensors"), metadata=None)
