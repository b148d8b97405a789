"""Task sequences: a scenario's ``"job"`` key, the steps run at every target, and their order.

A job names what the robot does at each target after the learned approach brings the tool there:

* ``"unscrew"`` (the nut task): approach → engage (the socket over the nut, its axis within
  ``engage_tolerance``) → unscrew (a powered spindle turns the socket while the arm retracts by the
  thread's pitch per turn) → retract with the nut → drop it into the ``bin``;
* ``"lift"`` (cell removal): approach → grasp (a vacuum gripper, made when the tool is within
  ``engage_tolerance`` of the part's top centre) → lift straight out past the neighbours → place
  in the next ``rack`` slot;
* ``"pick-place"``: approach → grasp → place in the next ``rack`` slot (no straight lift);
* ``"rock-lift"``: approach → grasp → rock (a periodic skill learned from the ``"rock"`` key's
  recording: ``cycles`` periods from rest and back to rest at the grasp, ``amplitude`` times the
  recorded swing, at the recorded frequency or ``frequency``, Hz) → lift → place, for a part held
  in its slot that has to be rocked loose first.

``"order"``: ``"listed"`` (the targets' order in the file) or ``"shortest"``: a short tour from
the demonstrated target by a small heuristic — nearest neighbour, then 2-opt exchanges until
none shortens it (not an optimal TSP solution; the distances come from SciPy's ``cdist``).

Lengths in the scenario's unit; every default is defined in millimetres and converted to it (a job
in metres or centimetres runs as the same job in mm). The bin and the rack are open boxes / slot
grids added to the scene's parts in the simulated world only (the evaluation's geometry is
unchanged).
"""

from __future__ import annotations

from dataclasses import dataclass
from numbers import Real

import numpy as np

from .._checks import (
    SLOWEST_HZ,
    as_point,
    as_vector,
    check_choice,
    check_int,
    check_real,
    short_token,
)
from .._units import UNITS, check_units, mm
from ._scenario_fields import _fail, _point, _shown

__all__ = ["JobSpec", "RockSpec", "JOB_KINDS", "parse_job", "tour"]

JOB_KINDS = {
    "unscrew": ("approach", "engage", "unscrew", "retract", "drop"),
    "lift": ("approach", "grasp", "lift", "place"),
    "pick-place": ("approach", "grasp", "place"),
    "rock-lift": ("approach", "grasp", "rock", "lift", "place"),
}
MAX_TOUR = 200
_KEYS = {
    "steps",
    "order",
    "bin",
    "rack",
    "pitch",
    "spindle_speed",
    "engage_tolerance",
    "part_mass",
    "lift",
    "clearance",
    "transfer",
    "rock",
}


# The defaults, in mm (converted to the scenario's unit).
DEFAULTS_MM = {"pitch": 1.25, "engage_tolerance": 1.0, "lift": 20.0, "clearance": 40.0}
PLAY_MM = 0.5  # a part is let go this far above where it rests; a nut leaves its stud this far clear of it
SLOT_TOLERANCE_MM = 1.0  # a placed part's bottom within this of its slot's height


@dataclass(frozen=True)
class RockSpec:
    """The ``"rock"`` step of a job: the bundled recording its periodic skill is learned from
    (:func:`bidmp.demonstrations.recording_names`), the periods to run, the swing as a multiple of
    the recorded one, and the frequency (Hz; None: the recorded one)."""

    recording: str
    cycles: float = 3.0
    amplitude: float = 1.0
    frequency: float | None = None

    def __post_init__(self) -> None:
        from ..demonstrations.datasets import recording_names

        check_choice(self.recording, "recording", recording_names())
        object.__setattr__(
            self, "cycles", check_real(self.cycles, "cycles", positive=True, maximum=1000)
        )
        object.__setattr__(
            self, "amplitude", check_real(self.amplitude, "amplitude", positive=True, maximum=100)
        )
        if self.frequency is not None:
            object.__setattr__(
                self,
                "frequency",
                check_real(self.frequency, "frequency", minimum=SLOWEST_HZ, maximum=50),
            )


@dataclass(frozen=True)
class JobSpec:
    """A validated ``"job"`` (lengths in ``units``, times in s, masses in kg; a length left out is
    its default in mm, :data:`DEFAULTS_MM`, converted to ``units``).

    ``bin``: (where it stands: its bottom's centre (3,), inner size (3,)), an open box whose floor
    and walls are :attr:`bin_wall` thick; ``rack``: (first slot (3,), step
    between slots (3,), slots per row, step between rows (3,)); ``pitch``: thread pitch per turn;
    ``spindle_speed``: the socket's top speed, turns/s; ``lift``: how far above a part's
    neighbours it is lifted; ``clearance``: the height over the work the transfers keep;
    ``transfer``: how a move to the bin or the rack is made from the learned skill — ``"dmp"``,
    the DMP's start and goal generalisation, or ``"similarity"``, its reproduction turned,
    scaled and moved so that it runs from the start to the goal (for a skill whose shape is a
    long arc that the DMP would carry, whole, into a short move).
    """

    kind: str
    steps: tuple
    order: str = "listed"
    bin: tuple | None = None
    rack: tuple | None = None
    pitch: float | None = None
    spindle_speed: float = 10.0
    engage_tolerance: float | None = None
    part_mass: float = 0.005
    lift: float | None = None
    clearance: float | None = None
    transfer: str = "dmp"
    units: str = "mm"
    rock: RockSpec | None = None

    def __post_init__(self) -> None:
        kind = check_choice(self.kind, "kind", JOB_KINDS)
        if not isinstance(self.steps, (tuple, list)) or tuple(self.steps) != JOB_KINDS[kind]:
            raise ValueError(
                f"steps must be {' -> '.join(JOB_KINDS[kind])} for a {kind} job, got {short_token(self.steps, 40)}"
            )
        object.__setattr__(self, "steps", tuple(self.steps))
        check_choice(self.order, "order", ("listed", "shortest"))
        check_choice(self.transfer, "transfer", ("dmp", "similarity"))
        units = check_units(self.units)
        if units not in UNITS:
            raise ValueError(
                f"units must be a length unit ({', '.join(UNITS)}), got {short_token(units)}"
            )
        for name, value in DEFAULTS_MM.items():
            object.__setattr__(
                self,
                name,
                mm(value, units)
                if getattr(self, name) is None
                else check_real(getattr(self, name), name, positive=True),
            )
        for name in ("spindle_speed", "part_mass"):
            object.__setattr__(self, name, check_real(getattr(self, name), name, positive=True))
        if self.bin is not None:
            if not isinstance(self.bin, (tuple, list)) or len(self.bin) != 2:
                raise TypeError(
                    f"bin must be (its bottom's centre (3,), inner size (3,)), got {short_token(self.bin, 30)}"
                )
            object.__setattr__(
                self,
                "bin",
                (
                    as_point(self.bin[0], 3, "bin[0]"),
                    as_vector(self.bin[1], "bin[1]", length=3, positive=True),
                ),
            )
        if self.rack is not None:
            if not isinstance(self.rack, (tuple, list)) or len(self.rack) != 4:
                raise TypeError(
                    f"rack must be (first slot (3,), step (3,), slots per row, row step (3,)), got "
                    f"{short_token(self.rack, 30)}"
                )
            first, step, per_row, row_step = self.rack
            object.__setattr__(
                self,
                "rack",
                (
                    as_point(first, 3, "rack[0]"),
                    as_point(step, 3, "rack[1]"),
                    check_int(per_row, "rack[2]", minimum=1),
                    as_point(row_step, 3, "rack[3]"),
                ),
            )
        if (kind == "rock-lift") != (self.rock is not None):
            raise ValueError(
                "rock: a rock-lift job rocks each part with a periodic skill (give RockSpec); "
                "no other job has a rock step"
            )
        if self.rock is not None and not isinstance(self.rock, RockSpec):
            raise TypeError(f"rock must be a RockSpec, got {type(self.rock).__name__}")
        if kind == "unscrew" and self.bin is None:
            raise ValueError(
                "bin: an unscrew job drops each nut into a bin; give where it stands and its size"
            )

    @property
    def play(self) -> float:
        """How far above where it rests a part is let go, and a nut clears its stud (scene units)."""
        return mm(PLAY_MM, self.units)

    @property
    def slot_tolerance(self) -> float:
        """How far a placed part's bottom may be from its slot's height (scene units)."""
        return mm(SLOT_TOLERANCE_MM, self.units)

    @property
    def bin_wall(self) -> float:
        """The bin's floor and walls' thickness (scene units): 2 % of its inner width (1.4 mm for a
        70 mm bin), at least 0.1 % of its largest inner size."""
        inner = np.asarray(self.bin[1], dtype=float)
        return max(0.02 * float(inner[:2].min()), 1e-3 * float(inner.max()))

    @property
    def bin_floor(self) -> np.ndarray:
        """The centre of the bin's inner floor (scene units): where it stands plus its floor."""
        return np.asarray(self.bin[0], dtype=float) + [0.0, 0.0, self.bin_wall]

    def slot(self, index: int) -> np.ndarray:
        """Where the ``index``-th part placed in the rack has its bottom centre (scene units)."""
        if self.rack is None:
            raise ValueError(f"index: this {self.kind} job has no rack to place parts in")
        index = check_int(index, "index", minimum=0, maximum=10**6)
        first, step, per_row, row_step = self.rack
        return first + (index % per_row) * step + (index // per_row) * row_step


def _positive(value, source: str, key: str) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, Real)
        or not np.isfinite(value)
        or value <= 0
    ):
        _fail(source, key, f"expected a positive number, got {_shown(value)}")
    return float(value)


def _box(value, source: str, key: str) -> tuple:
    if not isinstance(value, dict) or set(value) != {"at", "size"}:
        _fail(
            source,
            key,
            'expected {"at": [x, y, z] (its bottom\'s centre), "size": [sx, sy, sz] (inside)}',
        )
    size = _point(value["size"], source, f"{key}.size", 3)
    if np.any(size <= 0):
        _fail(source, f"{key}.size", "every side must be > 0")
    return _point(value["at"], source, f"{key}.at", 3), size


def _rack(value, source: str, key: str) -> tuple:
    known = {"at", "step", "per_row", "row_step"}
    if not isinstance(value, dict) or set(value) - known or not {"at", "step"} <= set(value):
        _fail(
            source,
            key,
            'expected {"at": first slot [x, y, z], "step": [dx, dy, dz], "per_row": n, "row_step": [...]}',
        )
    per_row = value.get("per_row", 1000)
    if isinstance(per_row, bool) or not isinstance(per_row, int) or per_row < 1:
        _fail(source, f"{key}.per_row", f"expected a positive integer, got {_shown(per_row)}")
    return (
        _point(value["at"], source, f"{key}.at", 3),
        _point(value["step"], source, f"{key}.step", 3),
        per_row,
        _point(value.get("row_step", [0, 0, 0]), source, f"{key}.row_step", 3),
    )


def parse_job(data, source: str) -> JobSpec | None:
    """The scenario's ``"job"`` validated key by key (None when it has none)."""
    if not isinstance(data, dict):
        raise TypeError(f"data must be a scenario's dict, got {type(data).__name__}")
    source = source if isinstance(source, str) else "<data>"
    job = data.get("job")
    if job is None:
        return None
    if not isinstance(job, dict) or set(job) - _KEYS:
        unknown = sorted(set(job) - _KEYS) if isinstance(job, dict) else []
        _fail(
            source,
            "job",
            f"expected keys among {sorted(_KEYS)}" + (f"; unknown {unknown}" if unknown else ""),
        )
    steps = job.get("steps")
    kinds = {names: kind for kind, names in JOB_KINDS.items()}
    if not isinstance(steps, list) or tuple(steps) not in kinds:
        choices = "; ".join(" → ".join(names) for names in JOB_KINDS.values())
        _fail(source, "job.steps", f"expected one of the sequences {choices}, got {_shown(steps)}")
    kind = kinds[tuple(steps)]
    order = job.get("order", "listed")
    if order not in ("listed", "shortest"):
        _fail(source, "job.order", f'expected "listed" or "shortest", got {_shown(order)}')
    if kind == "unscrew" and "bin" not in job:
        _fail(
            source,
            "job.bin",
            "unscrewing drops each nut into a bin: give where it stands (its bottom's centre) "
            "and its inner size",
        )
    if kind != "unscrew" and "rack" not in job:
        _fail(
            source,
            "job.rack",
            "a part is placed in a rack slot: give the first slot and the step between slots",
        )
    transfer = job.get("transfer", "dmp")
    if transfer not in ("dmp", "similarity"):
        _fail(source, "job.transfer", f'expected "dmp" or "similarity", got {_shown(transfer)}')
    rock = None
    if (kind == "rock-lift") != ("rock" in job):
        _fail(
            source,
            "job.rock",
            'a rock step needs its periodic skill: {"recording": <a bundled recording>, '
            '"cycles": 3, "amplitude": 1} (and only a rock-lift job has one)',
        )
    if "rock" in job:
        rock = _rock(job["rock"], source)
    numbers = {
        name: _positive(job[name], source, f"job.{name}")
        for name in ("pitch", "spindle_speed", "engage_tolerance", "part_mass", "lift", "clearance")
        if name in job
    }
    units = data.get("units", "mm") if isinstance(data.get("units", "mm"), str) else "mm"
    return JobSpec(
        kind=kind,
        steps=tuple(steps),
        order=order,
        transfer=transfer,
        bin=_box(job["bin"], source, "job.bin") if "bin" in job else None,
        rack=_rack(job["rack"], source, "job.rack") if "rack" in job else None,
        units=units,
        rock=rock,
        **numbers,
    )


def _rock(value, source: str) -> RockSpec:
    """The ``"rock"`` key: a bundled recording's name, optional cycles, amplitude, frequency."""
    from ..demonstrations.datasets import recording_names

    keys = {"recording", "cycles", "amplitude", "frequency"}
    if not isinstance(value, dict) or "recording" not in value or set(value) - keys:
        _fail(source, "job.rock", f"expected keys among {sorted(keys)}, recording required")
    if value["recording"] not in recording_names():
        _fail(
            source,
            "job.rock.recording",
            f"expected a bundled recording ({', '.join(recording_names())}), got "
            f"{_shown(value['recording'])}",
        )
    numbers = {
        name: _positive(value[name], source, f"job.rock.{name}")
        for name in ("cycles", "amplitude", "frequency")
        if name in value
    }
    try:
        return RockSpec(value["recording"], **numbers)
    except ValueError as exc:
        _fail(source, "job.rock", str(exc))


def tour(points: np.ndarray, start: np.ndarray) -> list[int]:
    """A short open tour through ``points`` (n, 3) from ``start`` (3,): the visiting order, by
    nearest neighbour then 2-opt (a heuristic: short, not proven shortest)."""
    from scipy.spatial.distance import cdist

    from .._checks import as_point, as_points

    points = as_points(points, 3, "points")
    start = as_point(start, 3, "start")
    n = len(points)
    if n > MAX_TOUR:  # 2-opt here is O(n^4): a job's targets, not a point cloud
        raise ValueError(f"points: {n:,} targets; a tour orders at most {MAX_TOUR}")
    if n < 2:
        return list(range(n))
    distance = cdist(points, points)
    first = cdist(np.asarray(start, float)[None], points)[0]
    order, left = [int(np.argmin(first))], set(range(n)) - {int(np.argmin(first))}
    while left:
        here = order[-1]
        order.append(min(left, key=lambda j: (distance[here, j], j)))
        left.remove(order[-1])

    def length(path):
        return first[path[0]] + sum(distance[a, b] for a, b in zip(path, path[1:]))

    improved = True
    while improved:  # 2-opt: reverse a stretch while that shortens the tour
        improved = False
        for i in range(n - 1):
            for j in range(i + 1, n):
                candidate = order[:i] + order[i : j + 1][::-1] + order[j + 1 :]
                if length(candidate) < length(order) - 1e-9:
                    order, improved = candidate, True
    return order
