"""The model check: every "done when" figure of issue 14 measured on one model folder.

``benchmarks/model_check.py`` is the command; this package holds the logic:
:mod:`.config` (settings, prompts), :mod:`.samples` (prompt sets with fixed noise),
:mod:`.split` (test-split protocol), :mod:`.detect` and :mod:`.prompts` (jumps, speeds),
:mod:`.response` (gravity and wind against the simulator), :mod:`.verdict` (PASS/FAIL from
numbers), :mod:`.report` (check.md), :mod:`.run` (:class:`ModelCheck`).
"""

from simdiff.eval.model_check.config import CheckConfig, quick_preset
from simdiff.eval.model_check.run import ModelCheck
from simdiff.eval.model_check.verdict import figures, verdicts

__all__ = ["CheckConfig", "ModelCheck", "figures", "quick_preset", "verdicts"]
