"""Run a script (benchmarks/model_check.py) with guidance only at t <= T_HI (interval_probe.patch):
T_HI=600 python interval_wrap.py benchmarks/model_check.py ARGS... (session 62 screen; the check's fingerprint does not
know the patch, so give it an output folder of its own)."""
import os
import runpy
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from interval_probe import patch  # noqa: E402

patch(int(os.environ.get("T_HI", "600")), int(os.environ.get("T_LO", "0")))
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
