"""``simdiff serve``: a local web viewer — 3D skeleton player, prompt box, gravity/wind/α sliders.

:class:`~simdiff.serve.service.MotionService` generates and opens motions;
:class:`~simdiff.serve.server.ViewerServer` serves the page (``static/``) and its JSON API.
"""

from simdiff.serve.params import GenerateParams, parse_generate
from simdiff.serve.server import ViewerServer
from simdiff.serve.service import (
           ListedMotion,
           ModelUnavailable,
           MotionService,
           read_listed,
)

__all__ = ["GenerateParams", "ListedMotion", "ModelUnavailable", "MotionService", "ViewerServer", "parse_generate",
           "read_listed"]
