"""Rendering: plan a scenario (trajectories, depths, appearance), then compose frames.

:mod:`~scenegen.render.plan` turns a config into a plan and renders it,
:mod:`~scenegen.render.draw` draws entity templates, :mod:`~scenegen.render.motion` holds
the AR2 paths and :mod:`~scenegen.render.compose` the compiled compositor;
:mod:`~scenegen.render.textures` loads image sources and draws value noise,
:mod:`~scenegen.render.camera` plans the camera's pan and zoom and
:mod:`~scenegen.render.photometric` applies motion blur, illumination and JPEG.
"""

from scenegen.render.plan import Scenario, generate, plan

__all__ = ["Scenario", "generate", "plan"]
