"""Session 52: run a script (benchmarks/model_check.py, float_probe.py) with every generated motion that never touches
the floor lowered onto it after the foot cleanup (simdiff.motion.floor.drop_floating) -- rule 32's candidate before
the package's cleanup 3 did the same.

usage: python reports/training/s52_runs_lowg/dropped.py SCRIPT [ARGS...]
The model check's fingerprint carries foot_cleanup "2+drop", so no stored part of the plain runs is reused."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "s51_floor"))
from floored import run_with  # noqa: E402

from simdiff.motion.floor import drop_floating  # noqa: E402

if __name__ == "__main__":
    run_with(drop_floating, "2+drop")
