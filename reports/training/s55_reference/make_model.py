"""Rebuild rule 50's candidate model folder (J40m_sa) without training: python make_model.py OUT
The shipped model (simdiff/assets/default_model, J40m) with the tensors of J40m_sa_adapters.safetensors (the Sim Encoder
and adapters after 1,000 source-anchored steps, session 55) put in; provenance from J40m_sa_provenance.json."""
import shutil
import sys
from pathlib import Path

from safetensors.torch import load_file, save_file

HERE, SHIPPED = Path(__file__).parent, Path(__file__).parents[3] / "simdiff/assets/default_model"
out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
for name in ("config.json", "sampling.json"):
    shutil.copyfile(SHIPPED / name, out / name)
shutil.copyfile(HERE / "J40m_sa_provenance.json", out / "provenance.json")
tensors = load_file(SHIPPED / "model.safetensors")
new = load_file(HERE / "J40m_sa_adapters.safetensors")
assert set(new) <= set(tensors), "unknown tensor names"
tensors.update(new)
save_file(tensors, out / "model.safetensors")
print("wrote", out, f"({len(new)} of {len(tensors)} tensors from the candidate)")
