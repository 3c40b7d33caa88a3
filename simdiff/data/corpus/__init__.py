"""One corpus from every motion source under ``../shared/data`` (``simdiff data build``).

Per source a small module with ``discover(shared_root, cache) -> list[Item]``; a registry
(:mod:`.registry`) joins them, filters by licence and deduplicates copies of one capture;
:mod:`.build` retargets, windows, mirrors and writes the HumanML3D layout.
"""
