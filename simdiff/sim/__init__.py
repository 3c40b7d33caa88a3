"""Physics projection P_φ,π: generated MuJoCo humanoid, environment φ, conversions, tracker, rollouts.

Modules: ``humanoid`` (MJCF builder), ``env`` (φ and validation), ``retarget`` (package: IK, contacts,
filtering, ID screen, :func:`make_reference`; ``convert`` is its old name, kept as a shim), ``tracker`` (Tracker interface, default PD tracker),
``residual`` (contact-gated root residual), ``rollout`` (one simulation + invariant audit),
``project`` (``project(joints, env) -> (rollout, info)``), ``pool`` (process / Ray parallelism),
``synthetic`` (test motions). MuJoCo is imported lazily.
"""
