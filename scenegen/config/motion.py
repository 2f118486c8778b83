"""Motion of an entity: the :class:`AR2` autoregression of one coordinate, and the
:class:`Motion` of an entity's centre and scale made of them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from scenegen.config.coerce import _coerce_fields
from scenegen.config.fields import AR2_FIELDS, _check_unused
from scenegen.config.messages import _fail, _short

__all__ = ["AR2", "Boundary", "Motion"]

Boundary = Literal["reflect", "clamp", "free"]


@dataclass(frozen=True)
class AR2:
    """Second-order autoregression of one coordinate (docs/algorithms.md §1).

    ``c_t = mean + a1 (c_{t-1} - mean) + a2 (c_{t-2} - mean) + sigma * eps_t``.
    ``a1 = 2, a2 = -1`` is constant velocity plus acceleration noise; ``a1 = 1 + d,
    a2 = -d`` damps the velocity. ``mean`` defaults to the initial value.

    ``boundary`` (required) says what happens at the frame border: ``reflect`` mirrors the
    coordinate and its previous value (so the velocity reverses) about the limit, ``clamp``
    stops it at the limit with zero velocity, ``free`` lets the entity leave the frame. The
    limits keep the entity's centre at least ``margin`` pixels plus half its size inside the
    frame (for ``scale`` the limits are ``[-margin, margin]`` around the mean in log units,
    and a margin of 0 means no limit on the path; whatever the path, the scale an entity is
    drawn at, and its boxes, stay within 1/20 to 20 times its size, so a ``free`` log scale
    beyond log 20 draws and boxes it at that limit). An entity's ``reflect``/``clamp`` axis
    needs 2 x margin + its size <= the frame's side, else its config is refused. The limits
    hold from frame 1 on: a ``position`` outside them (nearer the border than ``margin``
    plus half the size) is taken as given at frame 0, and at frame 1 ``reflect`` mirrors it
    about the limit (a jump of twice its distance outside) and ``clamp`` puts it on the
    limit. Such starts are allowed (an entity may enter from outside the frame); give one
    inside ``[margin + size / 2, side - margin - size / 2]`` for a path without that jump.
    A ``free`` boundary has no limits: a ``margin`` on it is refused unless 0
    (:data:`AR2_FIELDS`).

    Any ``a1, a2`` is accepted, including explosive ones (roots of ``z^2 - a1 z - a2``
    outside the unit circle; ``a1 = 2, a2 = -1`` has a double root at 1, a random walk of
    the velocity, and is not explosive). A ``reflect`` or ``clamp`` axis stays within its
    limits whatever they are, but a ``free`` one (or an unbounded scale, gain or offset)
    of an explosive AR2 grows geometrically: a path beyond :data:`MAX_PATH` in magnitude is
    refused when the scene is planned, with a ConfigError naming the field and the frame
    (``entities[0].motion.x: the AR2 path reaches 1.2e+18 at frame 7, ...``).

    Attributes
    ----------
    boundary : {"reflect", "clamp", "free"}
        What happens at the limits (required).
    a1, a2 : float
        The autoregression coefficients. Defaults 2 and -1 (constant velocity).
    sigma : float
        Std of the noise ``eps_t`` (px; log units for a scale, zoom or gain; grey levels
        for an offset), >= 0. Default 0.
    mean : float or None
        The level the path reverts to; None: the initial value. Default None.
    margin : float
        Distance kept from the frame border (px) beyond half the entity's size; for a
        log scale, zoom, gain or offset the bound of ``|value|`` (0: none). >= 0; must be
        0 with ``free``. Default 0.

    Raises
    ------
    ConfigError
        ``sigma < 0``, ``margin < 0``, or a non-zero ``margin`` with ``free``; the
        message names the field.
    """

    boundary: Boundary
    a1: float = 2.0
    a2: float = -1.0
    sigma: float = 0.0
    mean: float | None = None
    margin: float = 0.0

    def __post_init__(self) -> None:
        _coerce_fields(self)
        if self.sigma < 0:
            _fail("sigma", f"must be >= 0, got {_short(self.sigma)}")
        if self.margin < 0:
            _fail("margin", f"must be >= 0, got {_short(self.margin)}")
        _check_unused(self, "boundary", AR2_FIELDS)


@dataclass(frozen=True)
class Motion:
    """Per-coordinate AR2 motion of an entity's centre (x, y) and, optionally, log scale.

    ``velocity`` sets the initial velocity: the value before the first frame is
    ``position - velocity``.

    Attributes
    ----------
    x, y : AR2
        Motion of the centre's x and y (px).
    scale : AR2 or None
        Motion of the log scale (from 0: the appearance's size); None: constant scale.
        Default None.
    velocity : tuple of (float, float)
        Initial (x, y) velocity of the centre (px/frame). Default ``(0, 0)``.
    """

    x: AR2
    y: AR2
    scale: AR2 | None = None
    velocity: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        _coerce_fields(self)
