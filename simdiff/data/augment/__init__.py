"""Simulator-augmented corpus: replay training clips under φ, filter, write HumanML3D layout + φ.

Modules: ``conditions`` (binary / random φ), ``filter`` (pure keep rule), ``projector``
(process pool / Ray / serial over :func:`simdiff.sim.project`), ``run`` (sharded, resumable
driver and report), ``dataset`` (items with ``env`` / ``env_index`` for adapter training).
"""

from simdiff.data.augment.conditions import AugmentEnv, binary_conditions, make_conditions, random_conditions
from simdiff.data.augment.dataset import AugmentedHumanML3D, open_training_dataset, read_env_table
from simdiff.data.augment.filter import FilterConfig, keep_pair
from simdiff.data.augment.run import AugmentConfig, augment

__all__ = ["AugmentConfig", "AugmentEnv", "AugmentedHumanML3D", "FilterConfig", "augment", "binary_conditions",
           "keep_pair", "make_conditions", "open_training_dataset", "random_conditions", "read_env_table"]
