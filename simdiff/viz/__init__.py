"""Rendering: stick-figure animations (GIF/MP4) and filmstrips (PNG) of (T, 22, 3) joints."""

from simdiff.viz.stick import animation_frames, render_animation, render_filmstrip

__all__ = ["animation_frames", "render_animation", "render_filmstrip"]
