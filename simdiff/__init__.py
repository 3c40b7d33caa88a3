"""simdiff: physically plausible text-to-motion under explicit gravity and wind.

Conventions used throughout: metres, seconds, Y-up, facing +Z at frame 0, 20 fps for
HumanML3D data; joints are ``(T, 22, 3)`` float32, features ``(T, 263)``.
"""

__version__ = "0.1.0"
