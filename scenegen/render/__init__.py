"""Rendering: plan a scenario (trajectories, depths, appearance), then compose frames.

:mod:`~scenegen.render.plan` turns a config into a plan and renders it,
:mod:`~scenegen.render.draw` draws entity templates, :mod:`~scenegen.render.motion` holds
the AR2 paths and :mod:`~scenegen.render.compose` the compiled compositor.
"""

from scenegen.render.plan import Scenario, generate, plan

__all__ = ["Scenario", "generate", "plan"]
