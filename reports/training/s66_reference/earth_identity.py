"""Does --anchor reference --anchor-alpha 0 at Earth give exactly the alpha-0 adapters-anchor samples (B reuse)?"""
import torch
from simdiff.model.generator import MotionGenerator
torch.set_num_threads(2)
g = MotionGenerator.load("reports/training/s63_deepen/G63_model")
texts = ["a person jumps forward", "a person walks in a circle", "someone runs", "a man waves"]
kw = dict(lengths=[60, 80, 40, 60], env=torch.tensor([-9.81, 0.0, 0.0]), steps=10, guidance=2.5, seed=5, foot_lock=1.0)
a = g.generate(texts, alpha=0.0, env_guidance=4.0, **kw)
b = g.generate(texts, alpha=0.5, env_guidance=3.0, anchor="reference", anchor_alpha=0.0, env_guidance_fallback=2.0, **kw)
c = g.generate(texts, alpha=0.5, env_guidance=3.0, anchor="backbone", anchor_alpha=0.0, env_guidance_fallback=2.0, **kw)
for name, o in (("reference", b), ("backbone", c)):
    for f in ("joints", "features"):
        if hasattr(a, f):
            x, y = getattr(a, f), getattr(o, f)
            print(name, f, (x - y).abs().max().item() if torch.is_tensor(x) else [abs(p - q).max() for p, q in zip(x, y)])
print([k for k in vars(a)])
