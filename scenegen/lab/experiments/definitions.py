"""The six experiments (the contract's five and ``dps-dancers``), as declarative definitions.

An :class:`Experiment` names the sequence preset(s), the methods (a tracker with fixed
parameters), an optional parameter sweep, the default number of runs R and what to change
in the quick ("scale down") mode used by tests and ``make demo``. The paper's figures for
each table live here too (:data:`PAPER`), next to the definitions they belong to.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from scenegen.errors import ConfigError

__all__ = ["DEMO_PLAN", "EXPERIMENTS", "PAPER", "Experiment", "Method", "get", "names"]


@dataclass(frozen=True)
class Method:
    """A tracker with fixed parameters, as one column of a paper's table.

    Attributes
    ----------
    label : str
        The name in tables and figures (e.g. ``"PS(2,3,1)"``).
    slug : str
        File-name-safe identifier, unique within the experiment.
    tracker : str
        Registry name (``trackers.make``).
    params : tuple of (str, value)
        Keyword parameters (``rng`` is added per run).
    group : str
        Methods with the same group are summarised together (e.g. ``"PS"`` for the PS
        orderings: mean and worst over them).
    """

    label: str
    slug: str
    tracker: str
    params: tuple[tuple[str, Any], ...] = ()
    group: str = ""

    def param_dict(self) -> dict[str, Any]:
        """The method's tracker parameters as keyword arguments.

        Returns
        -------
        dict of str to object
            Parameter name -> value, in the order of ``params``; tuple values become
            lists (one level: e.g. a PS ``ordering``).
        """
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.params}


@dataclass(frozen=True)
class Experiment:
    """One experiment: what is run, how often, and how it is scaled down.

    Attributes
    ----------
    name : str
        public name (``scenegen experiment NAME``).
    title : str
        What it reproduces.
    presets : tuple of str
        Sequence presets.
    methods : tuple of Method
        The compared methods (the table's columns).
    sweep : tuple of (str, tuple)
        At most one swept tracker parameter and its values (e.g. λ for DPS); empty for
        none. Every method runs at every value.
    runs : int
        Default number of tracker runs R per scene, method, sweep value and preset.
    scenes : int
        Default number of scenes S per preset: scene s has its own scene seed, shared by
        every method and run (runs are paired by (preset, scene, run)). An experiment
        runs S x R runs per method, preset and swept value.
    hard_target : str
        Name of the entity the paper treats separately (the distracted or occluded
        object), "" if none.
    quick_frames : int or None
        Frame count in quick mode (None keeps the preset's).
    quick_particles : int
        Cap on ``n_particles`` in quick mode.
    quick_sweep : tuple
        Sweep values kept in quick mode (empty keeps all).
    """

    name: str
    title: str
    presets: tuple[str, ...]
    methods: tuple[Method, ...]
    sweep: tuple[tuple[str, tuple[Any, ...]], ...] = ()
    runs: int = 5
    scenes: int = 10
    hard_target: str = ""
    quick_frames: int | None = None
    quick_particles: int = 40
    quick_sweep: tuple[Any, ...] = field(default=())

    def method(self, slug_or_label: str) -> Method:
        """The method with this slug or label.

        Parameters
        ----------
        slug_or_label : str
            A method's ``slug`` (e.g. ``"ps-123"``) or ``label`` (e.g. ``"PS(1,2,3)"``).

        Returns
        -------
        Method
            The first of ``methods`` whose slug or label it is.

        Raises
        ------
        ConfigError
            Listing the valid methods.
        """
        for m in self.methods:
            if slug_or_label in (m.slug, m.label):
                return m
        raise ConfigError(
            f"unknown method {slug_or_label!r} for experiment {self.name!r}; valid methods: "
            + ", ".join(m.slug for m in self.methods)
        )

    def sweep_values(self, quick: bool = False) -> list[tuple[str, Any]]:
        """``(parameter, value)`` pairs to run; ``[("", None)]`` without a sweep.

        Parameters
        ----------
        quick : bool, default False
            Quick mode: keep only the values in ``quick_sweep`` (all of them when
            ``quick_sweep`` is empty).

        Returns
        -------
        list of (str, object)
            The swept parameter's name with each of its values, in the order of ``sweep``.
        """
        if not self.sweep:
            return [("", None)]
        key, values = self.sweep[0]
        if quick and self.quick_sweep:
            values = tuple(v for v in values if v in self.quick_sweep)
        return [(key, v) for v in values]


def _ps_orderings(m: int) -> list[tuple[int, ...]]:
    # The paper's circular shifts (1, 2, ..., M), (2, ..., M, 1), ... (DPS §3.3), 0-based.
    return [tuple((s + i) % m for i in range(m)) for s in range(m)]


def _ps_methods(m: int, params: tuple[tuple[str, Any], ...]) -> list[Method]:
    out = []
    for order in _ps_orderings(m):
        label = "PS(" + ",".join(str(i + 1) for i in order) + ")"
        slug = "ps-" + "".join(str(i + 1) for i in order)
        out.append(Method(label, slug, "ps", (*params, ("ordering", order)), group="PS"))
    return out


_N300 = (("n_particles", 300),)
_N200 = (("n_particles", 200), ("lam", 20.0))

DPS_SYNTHETIC = Experiment(
    name="dps-synthetic",
    title="DPS Tables 1–2 and Fig. 4: seven objects and a distractor, N = 300, λ swept",
    presets=("dps-synthetic",),
    methods=(
        Method("Non-PS", "nonps", "joint-pf", _N300),
        *_ps_methods(7, _N300),
        Method("DPS", "dps", "dps", _N300),
    ),
    sweep=(("lam", (20.0, 30.0, 40.0, 50.0)),),
    runs=5,
    scenes=10,
    hard_target="object1",
    quick_frames=None,
    quick_particles=70,
    quick_sweep=(20.0,),
)

DPS_OCCLUSION = Experiment(
    name="dps-occlusion",
    title="DPS Table 3 (RealSeq1 and RealSeq2 analogues): the occluded walker, N = 200, λ = 20",
    presets=("dps-occlusion", "dps-occlusion-2"),
    methods=(
        Method("Non-PS", "nonps", "joint-pf", _N200),
        *_ps_methods(3, _N200),
        Method("DPS", "dps", "dps", _N200),
    ),
    runs=5,
    scenes=10,
    hard_target="walker",
    quick_frames=60,
    quick_particles=60,
)

# RealSeq3: four objects and 200 particles, so each of DPS's four components has 50. λ = 150
# (the same for every method; tuned, see the dps-dancers preset): a peaked likelihood, so
# that the number of particles weighing each dancer matters.
_N200_DANCERS = (("n_particles", 200), ("lam", 150.0))

DPS_DANCERS = Experiment(
    name="dps-dancers",
    title="DPS Table 4 (RealSeq3 analogue): four dancers, N = 200 (50 per DPS component), λ = 150",
    presets=("dps-dancers",),
    methods=(
        Method("Non-PS", "nonps", "joint-pf", _N200_DANCERS),
        *_ps_methods(4, _N200_DANCERS),
        Method("DPS", "dps", "dps", _N200_DANCERS),
    ),
    runs=5,
    scenes=10,
    hard_target="dancer4",
    quick_frames=20,
    quick_particles=60,
)

_KAMS_METHODS = (
    Method("Hybrid", "hybrid", "hybrid", (("n_particles", 100),)),
    Method("SOK", "sok", "sok"),
    Method("KAMS", "kams", "kams", (("n_particles", 40),)),
)

# 15 scenes x 2 runs = 30 per sequence (the paper ran 10): the claim "KAMS completes the
# sequence" is an exact one-sided binomial test of a completion rate above 50 %, and with the
# stated effect of interest, 75 % completion, 10 runs decide it with power 0.24 and 30 with
# 0.89 (α = 0.05; docs/experiments.md, "Scenes and runs"). Chosen in round 5 from that
# calculation, before the judged base seed was rerun.
KAMS_ACCURACY = Experiment(
    name="kams-accuracy",
    title="KAMS Fig. 7/8: mean centre error on sequences a–d (Hybrid N = 100, KAMS N = 40)",
    presets=("kams-a", "kams-b", "kams-c", "kams-d"),
    methods=_KAMS_METHODS,
    runs=2,
    scenes=15,
    quick_frames=40,
    quick_particles=20,
)

# The paper's McNemar cases are 36 real sequences; ours are S scenes of each of kams-a…d
# (9 x 4 = 36 by default), one run each, every method on the same scenes. Particle counts: the
# paper's tiger example gives 200 for the particle filters; Hybrid and KAMS keep the
# counts of the accuracy experiment (100 and 40), the paper's point being that KAMS needs
# fewer.
KAMS_ROBUSTNESS = Experiment(
    name="kams-robustness",
    title="KAMS Table 1: McNemar z of KAMS against five trackers over paired cases",
    presets=("kams-a", "kams-b", "kams-c", "kams-d"),
    methods=(
        Method("KAMS", "kams", "kams", (("n_particles", 40),)),
        Method("Condensation", "condensation", "condensation", (("n_particles", 200),)),
        Method("Mean Shift", "meanshift", "meanshift"),
        Method("Annealing", "annealed", "annealed", (("n_particles", 200),)),
        Method("Hybrid", "hybrid", "hybrid", (("n_particles", 100),)),
        Method("SOK", "sok", "sok"),
    ),
    runs=1,
    scenes=9,
    quick_frames=40,
    quick_particles=20,
)

# 40 scenes (20 until round 5): on the plain crossing Kalman rarely fails, so the claim "SHM
# keeps both targets more often than Kalman" can only be decided by ruling a 20-point lead
# out; if Kalman failed in 5 % of scenes and SHM in none, 20 scenes would decide it with
# probability 0.36, 40 with 0.86 (Newcombe interval below 20 points); at the effect of
# interest itself (Kalman failing in 20 % of scenes, SHM in none) the exact McNemar test
# finds it with probability 0.37 on 20 scenes and 0.92 on 40.
SHM_DEPTH = Experiment(
    name="shm-depth",
    title="SHM §5: depth-order accuracy and tracking through crossings (Kalman, SHM, fast SHM)",
    presets=("shm-crossing", "shm-clutter"),
    methods=(
        Method("Kalman", "kalman", "kalman"),
        Method("SHM", "shm", "shm"),
        Method("Fast SHM", "shm-fast", "shm-fast"),
    ),
    runs=1,
    scenes=40,
    quick_frames=45,
)

EXPERIMENTS: dict[str, Experiment] = {
    e.name: e
    for e in (DPS_SYNTHETIC, DPS_OCCLUSION, KAMS_ACCURACY, KAMS_ROBUSTNESS, SHM_DEPTH,
              DPS_DANCERS)
}

# Per experiment: (scenes S, runs R per scene, quick mode) of `make demo` (`scenegen demo`,
# always base seed 0). Chosen so that the whole demo (presets, previews, experiments,
# report) stays within 10 minutes on 2 cores; its verdicts are indicative. The full
# reproduction is `scenegen experiment all`, at each experiment's own S x R.
DEMO_PLAN: dict[str, tuple[int, int, bool]] = {
    "dps-synthetic": (4, 2, False),
    "dps-occlusion": (4, 2, False),
    "kams-accuracy": (3, 1, False),
    "kams-robustness": (3, 1, False),
    "shm-depth": (6, 1, False),
    "dps-dancers": (4, 2, False),
}

# The papers' figures, keyed like our summaries. Percentages unless marked.
PAPER: dict[str, Any] = {
    "dps-synthetic": {
        # Table 1, objects 2–7: success % and precision/recall % per λ.
        "table1": {
            20.0: {"success": (97, 100, 100), "pr": ((69, 69), (90, 87), (91, 86))},
            30.0: {"success": (97, 100, 100), "pr": ((69, 68), (91, 87), (90, 86))},
            40.0: {"success": (93, 100, 100), "pr": ((68, 68), (91, 88), (90, 87))},
            50.0: {"success": (96, 100, 100), "pr": ((67, 66), (91, 88), (90, 87))},
        },
        # Table 2, object 1: recovery % (Non-PS, PS mean, PS worst, DPS) and P/R %.
        "table2": {
            20.0: {"recovery": (2, 19, 10, 42), "pr": ((27, 28), (27, 26), (17, 16), (41, 36))},
            30.0: {"recovery": (2, 18, 8, 34), "pr": ((21, 21), (24, 24), (16, 16), (36, 36))},
            40.0: {"recovery": (0, 21, 16, 38), "pr": ((23, 22), (30, 29), (18, 17), (21, 22))},
            50.0: {"recovery": (2, 21, 12, 36), "pr": ((24, 23), (28, 28), (25, 24), (23, 23))},
        },
    },
    "dps-occlusion": {
        # Table 3, object 1: success, recovery, precision, recall %; per sequence.
        "dps-occlusion": {  # RealSeq1
            "Non-PS": (32, 78, 59, 98),
            "PS(1,2,3)": (18, 18, 60, 98),
            "PS(2,3,1)": (40, 96, 58, 98),
            "PS(3,1,2)": (34, 52, 62, 99),
            "DPS": (100, 100, 62, 100),
        },
        "dps-occlusion-2": {  # RealSeq2
            "Non-PS": (10, 32, 72, 86),
            "PS(1,2,3)": (0, 8, 55, 91),
            "PS(2,3,1)": (12, 40, 72, 86),
            "PS(3,1,2)": (0, 8, 59, 91),
            "DPS": (78, 88, 58, 98),
        },
    },
    "dps-dancers": {
        # Table 4, RealSeq3, object 4: success, recovery, precision, recall %.
        "dps-dancers": {
            "Non-PS": (4, 8, 41, 70),
            "PS(1,2,3,4)": (26, 28, 46, 77),
            "PS(2,3,4,1)": (82, 86, 52, 87),
            "PS(3,4,1,2)": (84, 88, 51, 87),
            "PS(4,1,2,3)": (70, 72, 51, 86),
            "DPS": (36, 38, 51, 79),
        },
    },
    "kams-accuracy": {
        # §3.1: mean centre error in px on a–d; None = the tracker failed on it.
        "Hybrid": (6.32, None, None, None),
        "SOK": (5.66, 9.60, None, None),
        "KAMS": (6.94, 18.17, 14.72, 17.30),
    },
    "kams-robustness": {
        # Table 1: z of KAMS against each tracker (36 real sequences).
        "Condensation": 2.910428,
        "Mean Shift": 5.126524,
        "Annealing": 3.801316,
        "Hybrid": 4.828079,
        "SOK": 3.590662,
    },
}


def names() -> list[str]:
    """The experiment names: the contract's five in its order, then ``dps-dancers``.

    Returns
    -------
    list of str
        The keys of :data:`EXPERIMENTS`, in order.

    Examples
    --------
    >>> names()[-1]
    'dps-dancers'
    """
    return list(EXPERIMENTS)


def get(name: str) -> Experiment:
    """The experiment called ``name``.

    Parameters
    ----------
    name : str
        One of :func:`names`.

    Returns
    -------
    Experiment
        Its definition in :data:`EXPERIMENTS`.

    Raises
    ------
    ConfigError
        For an unknown name, listing the valid ones.
    """
    if name not in EXPERIMENTS:
        raise ConfigError(
            f"unknown experiment {name!r}; valid experiments: {', '.join(EXPERIMENTS)}"
        )
    return EXPERIMENTS[name]
