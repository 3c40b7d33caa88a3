"""Licences of the motion data: the codes recorded per clip in a corpus manifest and what they mean.

Read by the corpus builder (per clip) and by the model provenance (which licence the weights inherit),
so the table sits below both.
"""

from __future__ import annotations

LICENCES: dict[str, str] = {
    "CMU": "CMU Graphics Lab mocap terms: free for all uses, data may not be resold",
    "MIT": "MIT (repository licence of the files)",
    "CC-BY-SA-3.0": "Creative Commons Attribution-ShareAlike 3.0 (derived data shared alike)",
    "CC-BY-NC-4.0": "Creative Commons Attribution-NonCommercial 4.0 (non-commercial use only)",
}
"""Licence code -> meaning, as recorded per clip in the manifest."""

LICENCE_SETS: dict[str, frozenset[str]] = {
    "all": frozenset(LICENCES),
    "permissive": frozenset({"CMU", "MIT"}),
}
"""``--licence`` choices: ``all`` (research use) and ``permissive`` (no NC, no share-alike)."""
