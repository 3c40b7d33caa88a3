"""Session 51: run a script (benchmarks/model_check.py, float_probe.py) with every generated motion put on the floor
after the foot cleanup (simdiff.motion.floor.place_on_floor) -- the candidate of rule 30, before any plumbing.

usage: python reports/training/s51_floor/floored.py SCRIPT [ARGS...]
The model check's fingerprint carries foot_cleanup "2+floor", so no stored part of the unfloored runs is reused.
Session 52's dropped.py runs the same way with another post-process (run_with)."""
import runpy
import sys
from typing import Callable


def run_with(post: Callable, tag: str) -> None:
    """Run sys.argv[1:] as a script with ``post(features, lengths)`` applied after the generator's foot cleanup."""
    import simdiff.eval.model_check.run as R
    import simdiff.motion.foot_lock as FL

    clean = FL.clean_feet

    def clean_then_post(features, lengths=None, strength=1.0):
        return post(clean(features, lengths, strength), lengths)

    FL.clean_feet = clean_then_post  # the generator imports it from the module at call time
    R.CLEANUP_VERSION = tag
    sys.argv = sys.argv[1:]
    runpy.run_path(sys.argv[0], run_name="__main__")


if __name__ == "__main__":
    from simdiff.motion.floor import place_on_floor

    run_with(place_on_floor, "2+floor")
