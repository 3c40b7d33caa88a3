"""One training or evaluation batch from dataset items: the stacking that the trainer and the evaluators share."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import torch

from simdiff.errors import SimdiffError


def collate(items: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Stack items: motion (B, T, 263), lengths (B,), mask (B, T) bool, captions, and env / env_index when present."""
    if not items:
        raise SimdiffError("cannot collate an empty batch")
    motion = torch.stack([torch.as_tensor(np.asarray(it["motion"]), dtype=torch.float32) for it in items])
    lengths = torch.tensor([int(it["length"]) for it in items], dtype=torch.long)
    batch: dict[str, Any] = {
        "motion": motion,
        "lengths": lengths,
        "mask": torch.arange(motion.shape[1])[None, :] < lengths[:, None],
        "captions": [str(it["caption"]) for it in items],
    }
    if all("env" in it for it in items):
        batch["env"] = torch.stack([torch.as_tensor(np.asarray(it["env"]), dtype=torch.float32).reshape(3) for it in items])
    if all("env_index" in it for it in items):
        batch["env_index"] = torch.tensor([int(it["env_index"]) for it in items], dtype=torch.long)
    return batch
