"""Ship rule 57's candidate X15sa: python ship57.py [MODEL_DIR] (default simdiff/assets/default_model).
Copies X15sa's model.safetensors (the lambda 1.5 backbone and its source-anchored adapters; same architecture, so
config.json and sampling.json stay and are checked identical), writes its provenance with the session-57 steps
described, and writes extrapolation.json (how the backbone was made), which `simdiff generate` copies into
generation.json."""
import hashlib
import json
import shutil
import sys
from pathlib import Path

SRC = Path("/work/scratch/s57/X15sa_model")
RECIPE = Path("/work/scratch/s57/wx1.5/extrapolation.json")
BACKBONE = ("session 57: that backbone extrapolated in weight space, theta = theta_41 + 1.5 (theta_41 - theta_25) "
            "(`simdiff train extrapolate --lam 1.5`; parent: the backbone shipped at 1c859a7), shipped by "
            "reports/training/s57_pooled_a/rule57.txt")
ADAPTERS = ("session 57: the session-41/52 shipped adapters fine-tuned 1,000 steps of batch 64 on the extrapolated "
            "backbone on 2 CPU cores (15 min; lambda 10, mu 20, lr 1e-4, seed 55; "
            "configs/adapters_paired_gpu_finetune.json) on source-anchored targets (`simdiff train adapters --targets "
            "source-anchored`: x_source + (x_sim(phi) - x_sim(Earth)); 3,362 of 4,686 first-try items of aug_weakg, "
            "aug_gen and aug_wind anchored, the rest keep the replay); shipped by "
            "reports/training/s57_pooled_a/rule57.txt")

out = Path(sys.argv[1] if len(sys.argv) > 1 else "simdiff/assets/default_model")
for name in ("config.json", "sampling.json"):
    assert json.loads((SRC / name).read_text()) == json.loads((out / name).read_text()), f"{name} differs"
shutil.copyfile(SRC / "model.safetensors", out / "model.safetensors")
prov = json.loads((SRC / "provenance.json").read_text())
backbones = [p for p in prov["trained_on"] if p["what"] == "backbone"]
assert len(backbones) == 2 and backbones[1]["note"].startswith("session 41"), "expected the session-25 and -41 entries"
backbones[1]["note"] += f"; {BACKBONE}"
fresh = [p for p in prov["trained_on"] if p["note"] == "simulated from corpus corpus3; trained on source-anchored targets"]
assert len(fresh) == 3, "expected the three session-57 adapter entries"
for p in fresh:
    p["note"] += f"; {ADAPTERS}"
(out / "provenance.json").write_text(json.dumps(prov, indent=2) + "\n")
recipe = json.loads(RECIPE.read_text())
recipe.update(model="the session-52 shipped model (backbone: session 41's jump fine-tune)",
              parent="simdiff/assets/default_model at commit 1c859a7 (the session-25 backbone)")
(out / "extrapolation.json").write_text(json.dumps(recipe, indent=2) + "\n")
digest = hashlib.sha256((out / "model.safetensors").read_bytes()).hexdigest()
print("wrote", out, f"(model.safetensors sha256 {digest[:16]}…; provenance {len(prov['trained_on'])} entries)")
