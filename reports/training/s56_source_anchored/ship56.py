"""Ship rule 51's candidate: python ship56.py [MODEL_DIR [RULE]] (default simdiff/assets/default_model and session 56's
rule51.txt; session 57 passes its own rule file, the rule that decided the shipping, named in the provenance).
Puts J40m_sa's Sim Encoder and adapter tensors (s55_reference/J40m_sa_adapters.safetensors) into MODEL_DIR's weights
and writes its provenance (s55_reference/J40m_sa_provenance.json) with the session-55 fine-tune described. config.json
and sampling.json stay: the same architecture and the same sampling settings."""
import json
import sys
from pathlib import Path

from safetensors.torch import load_file, save_file

REF = Path(__file__).parents[1] / "s55_reference"
NOTE = ("session 55: the session-54 adapters fine-tuned 1,000 steps of batch 64 on 2 CPU cores (16 min; lambda 10, mu "
        "20, lr 1e-4, seed 55; configs/adapters_paired_gpu_finetune.json) on source-anchored targets "
        "(`simdiff train adapters --targets source-anchored`: x_source + (x_sim(phi) - x_sim(Earth)) from corpus3's "
        "source clips; 3,362 of 4,686 first-try items anchored, the rest keep the replay); shipped by ")
out = Path(sys.argv[1] if len(sys.argv) > 1 else "simdiff/assets/default_model")
NOTE += sys.argv[2] if len(sys.argv) > 2 else "reports/training/s56_source_anchored/rule51.txt"
tensors = load_file(out / "model.safetensors")
new = load_file(REF / "J40m_sa_adapters.safetensors")
assert set(new) <= set(tensors) and all(k.startswith(("sim_encoder.", "adapters.")) for k in new), \
    "J40m_sa_adapters.safetensors holds more than the Sim Encoder and adapters"
tensors.update(new)
save_file(tensors, out / "model.safetensors")
prov = json.loads((REF / "J40m_sa_provenance.json").read_text())
fresh = [p for p in prov["trained_on"] if p["note"] == "simulated from corpus corpus3"]
assert len(fresh) == 3, "expected the three session-55 adapter entries"
for p in fresh:
    p["note"] = f"{p['note']}; {NOTE}"
(out / "provenance.json").write_text(json.dumps(prov, indent=2) + "\n")
print("wrote", out, f"({len(new)} of {len(tensors)} tensors replaced; provenance: {len(prov['trained_on'])} entries)")
