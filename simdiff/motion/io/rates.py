"""Frame-rate hints that override a wrong BVH header.

The acLSTM dance folders (``aclstm/{salsa,martial,indian}/NN.bvh``) come with a
``readme.txt`` giving each folder's capture rate ("salsa  framerate 60"). Every header
says 120 fps, but the salsa takes are CMU subjects 60/61, which ``CMU_data.csv`` lists at
60 fps, and at 120 fps each foot would step 2.0-2.4 times a second (a 330 bpm salsa); at
60 fps it is 1.0-1.2 (about 170 bpm). The readme is therefore trusted over the header.
"""

from __future__ import annotations

import re
from pathlib import Path

_RATE_LINE = re.compile(r"^\s*(\S+)\s+frame\s*rate\s*[:=]?\s*([0-9]+(?:\.[0-9]+)?)\s*$", re.IGNORECASE)


def folder_fps_hint(path: str | Path) -> float | None:
    """Frame rate of ``path``'s folder stated in a ``readme.txt`` one level up, or None.

    The readme line must read ``<folder name> framerate <fps>`` (case-insensitive, any
    spacing, optional ``:``); e.g. ``salsa  framerate 60`` for ``salsa/01.bvh``.
    """
    path = Path(path)
    folder = path.parent.name
    for name in ("readme.txt", "README.txt", "README.TXT"):
        readme = path.parent.parent / name
        if not readme.is_file():
            continue
        try:
            lines = readme.read_text(encoding="utf-8", errors="replace").splitlines()
        except OSError:
            return None
        for line in lines:
            match = _RATE_LINE.match(line)
            if match and match.group(1) == folder and float(match.group(2)) > 0:
                return float(match.group(2))
        return None
    return None
