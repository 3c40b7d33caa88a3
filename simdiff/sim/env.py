"""The physical environment φ = (g_z, w_x, w_y) and how it enters the simulation.

* Gravity ``g_z`` in m/s² (Earth −9.81), along the world vertical (MuJoCo +z is up).
* Wind ``(w_x, w_y)`` in newtons: the **total horizontal force** on the character, along
  HumanML3D's x and z axes respectively (world x = HumanML3D z, world y = HumanML3D x; see
  :mod:`simdiff.sim.humanoid`). ``w_x`` is along HumanML3D +X (the character's left at frame
  0) and ``w_y`` along HumanML3D +Z (its facing direction at frame 0).

How wind is applied: as a uniform horizontal force field distributed over the body in
proportion to mass, i.e. every body of mass m_i receives ``m_i · w / M``; this is exactly a
horizontal component ``w / M`` (m/s²) added to ``model.opt.gravity``. It is exact, costs
nothing, puts no torque about the centre of mass, and sums to ``w`` N on the whole body
(10 N on 72 kg is 0.139 m/s²). MuJoCo's own ``opt.wind`` (a medium velocity with drag) is
not used, so there is no air drag from the body's own motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError

EARTH_GRAVITY: float = -9.81
GRAVITY_RANGE: tuple[float, float] = (-20.0, -1.0)
"""Validated gravity range (m/s²)."""
MAX_WIND: float = 10.0
"""Validated wind magnitude bound (N)."""
MIN_FORCED_GRAVITY: float = -100.0
MAX_GRAVITY: float = -0.1
"""Gravity bounds (m/s²) even with ``--force``: beyond them the simulator and the model give no motion."""
MAX_FORCED_WIND: float = 200.0
"""Wind component bound (N) even with ``--force``."""


@dataclass(frozen=True)
class Environment:
    """φ = (g_z, w_x, w_y).

    Attributes:
        gravity: vertical gravity in m/s² (negative; Earth −9.81).
        wind_x: wind force along HumanML3D +X in newtons.
        wind_y: wind force along HumanML3D +Z (forward at frame 0) in newtons.
    """

    gravity: float = EARTH_GRAVITY
    wind_x: float = 0.0
    wind_y: float = 0.0

    def validate(self, force: bool = False) -> "Environment":
        """Check the validated ranges g_z ∈ [−20, −1] and |w| ≤ 10 N.

        Args:
            force: widen the check to g_z ∈ [−100, −0.1] and |w_x|, |w_y| ≤ 200 N.
        Returns:
            self, for chaining.
        Raises:
            SimdiffError: naming the offending value.
        """
        vals = np.array([self.gravity, self.wind_x, self.wind_y], dtype=float)
        if not np.all(np.isfinite(vals)):
            raise SimdiffError(f"environment values must be finite, got {self}")
        if self.gravity >= 0:
            raise SimdiffError(f"gravity must be negative (m/s², Earth -9.81), got {self.gravity}")
        if not MIN_FORCED_GRAVITY <= self.gravity <= MAX_GRAVITY:
            raise SimdiffError(f"gravity {self.gravity:g} m/s² is outside [{MIN_FORCED_GRAVITY:g}, {MAX_GRAVITY:g}]")
        if max(abs(self.wind_x), abs(self.wind_y)) > MAX_FORCED_WIND:
            raise SimdiffError(f"wind ({self.wind_x:g}, {self.wind_y:g}) N has a component beyond ±{MAX_FORCED_WIND:g} N")
        if force:
            return self
        lo, hi = GRAVITY_RANGE
        if not lo <= self.gravity <= hi:
            raise SimdiffError(
                f"gravity {self.gravity} m/s² is outside the validated range [{lo}, {hi}] (use --force)"
            )
        w = float(np.hypot(self.wind_x, self.wind_y))
        if w > MAX_WIND + 1e-9:
            raise SimdiffError(
                f"wind |({self.wind_x}, {self.wind_y})| = {w:.3g} N exceeds the validated {MAX_WIND} N (use --force)"
            )
        return self

    @property
    def wind_world(self) -> np.ndarray:
        """(3,) wind force in MuJoCo world coordinates (N)."""
        return np.array([self.wind_y, self.wind_x, 0.0])

    def gravity_vector(self, total_mass: float) -> np.ndarray:
        """(3,) ``model.opt.gravity`` (m/s²) that realises gravity plus the mass-distributed wind."""
        return np.array([self.wind_y / total_mass, self.wind_x / total_mass, self.gravity])

    def apply(self, model, total_mass: float | None = None) -> None:
        """Write this environment into a MuJoCo model (``opt.gravity``; wind options off)."""
        mass = float(model.body_subtreemass[1]) if total_mass is None else total_mass
        model.opt.gravity[:] = self.gravity_vector(mass)
        model.opt.wind[:] = 0.0
        model.opt.density = 0.0
        model.opt.viscosity = 0.0

    def as_tuple(self) -> tuple[float, float, float]:
        """(g_z, w_x, w_y)."""
        return (float(self.gravity), float(self.wind_x), float(self.wind_y))
