# J62: the shipped backbone (session 41's jump fine-tune J40) fine-tuned 1,500 MORE steps with the same recipe
# (train_jumpx: the 198 flying jump ids drawn 8x, 20 % of draws; batch 64, lr 1e-4, EMA 0.999, unmasked as session 41
# trained; seed 62): the real continuation of the direction that `simdiff train extrapolate --lam 1` (X1) extrapolates.
# Resumable: a second call continues the run. Then the backbone is given the shipped adapters and config (mask at
# inference, as shipped) -> /work/scratch/s62/J62_model.
set -u
cd /work/main; . .venv/bin/activate
S=/work/scratch/s39; O=/work/scratch/s62; mkdir -p $O
[ -f $S/corpus3/train_jumpx.txt ] || python reports/training/s41_jump_backbone/jump_split.py $S/corpus3 8 > $S/corpus3/train_jumpx.txt
nice -n 5 simdiff train backbone --data $S/corpus3 --split train_jumpx --init simdiff/assets/default_model \
  --out $O/bb62 --config configs/backbone_small_cpu.json --lr 1e-4 --seed 62 --batch-size 64 --no-mask-frames \
  --steps 1500 --save-every 100 --device cpu --text-table .gpu/captions.safetensors --max-minutes ${MINUTES:-45} \
  --loader-workers 1 --no-progress || exit 1
python - $O/bb62/model $O/J62_model <<'PY'
# the shipped model with its backbone tensors replaced by the fine-tuned ones (adapters, Sim Encoder, settings shipped)
import json, shutil, sys
from pathlib import Path
from safetensors.torch import load_file, save_file
bb, out = Path(sys.argv[1]), Path(sys.argv[2])
ship = Path("simdiff/assets/default_model")
w, new = load_file(ship / "model.safetensors"), load_file(bb / "model.safetensors")
keys = [k for k in w if k.startswith("backbone.")]  # the backbone export names them without the prefix
assert all(k[9:] in new and new[k[9:]].shape == w[k].shape for k in keys), "backbone tensors differ in name or shape"
extra = sorted(set(new) - {k[9:] for k in keys})
assert all(k in w and (new[k] == w[k]).all() for k in extra), f"not the shipped normaliser: {extra}"
for k in keys:
    w[k] = new[k[9:]].to(w[k].dtype)
shutil.rmtree(out, ignore_errors=True); out.mkdir(parents=True)
save_file(w, str(out / "model.safetensors"))
for name in ("config.json", "sampling.json"):
    shutil.copyfile(ship / name, out / name)
print(f"{out}: {len(keys)} backbone tensors from {bb}")
PY
