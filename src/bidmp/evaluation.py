"""Evaluation of learned skills: metrics and worked examples.

For now this holds the LASA fit-and-generalise example behind ``bidmp demo`` and the G-PRM vs
classic PRM comparison behind ``bidmp reproduce table5``; the battery scenarios of SPEC §9 build
on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .datasets import lasa, minimum_jerk
from .dmp import DMP
from .extension import ExtendedDemonstration, extend_demonstration
from .incremental import BiDMP, ForgettingResult, forgetting, resample_time
from .roadmap import RoadmapResult, classic_prm, gaussian_prm

__all__ = [
    "rmse",
    "path_extent",
    "GeneralisationResult",
    "lasa_generalisation",
    "PRMComparison",
    "table5_cases",
    "compare_prm",
    "IncrementalResult",
    "lasa_incremental",
]


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    """Root-mean-square Euclidean distance between two trajectories of equal shape (T, D)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise ValueError(f"trajectories must have the same shape, got {a.shape} and {b.shape}")
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


def path_extent(y: np.ndarray) -> float:
    """Diagonal of the axis-aligned bounding box of a trajectory (same unit as ``y``)."""
    return float(np.linalg.norm(np.ptp(np.asarray(y, dtype=float), axis=0)))


@dataclass
class GeneralisationResult:
    """Outcome of :func:`lasa_generalisation` (lengths in the data set's unit, mm)."""

    shape: str
    demonstration: np.ndarray  # (T, D)
    reproduction: np.ndarray  # (T, D)
    goals: np.ndarray  # (G, D)
    fixed_horizon: np.ndarray  # (G, T, D): the paper's protocol, T steps
    converged: np.ndarray  # (G, n_converged, D)
    endpoint_gain: float
    endpoint_gain_converged: float
    dmp_params: dict = field(default_factory=dict)

    @property
    def extent(self) -> float:
        return path_extent(self.demonstration)

    @property
    def reproduction_rmse(self) -> float:
        return rmse(self.reproduction, self.demonstration)

    @property
    def goal_shifts(self) -> np.ndarray:
        return np.linalg.norm(self.goals - self.demonstration[-1], axis=1)

    @property
    def goal_error(self) -> float:
        """End-point error of the reproduction at the demonstrated goal (T steps)."""
        return float(np.linalg.norm(self.reproduction[-1] - self.demonstration[-1]))

    @property
    def errors_fixed(self) -> np.ndarray:
        return np.linalg.norm(self.fixed_horizon[:, -1] - self.goals, axis=1)

    @property
    def errors_converged(self) -> np.ndarray:
        return np.linalg.norm(self.converged[:, -1] - self.goals, axis=1)

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "shape": self.shape,
            "dmp": self.dmp_params,
            "n_samples": int(self.demonstration.shape[0]),
            "extent": self.extent,
            "reproduction_rmse": self.reproduction_rmse,
            "reproduction_rmse_percent": 100.0 * self.reproduction_rmse / self.extent,
            "endpoint_gain": self.endpoint_gain,
            "endpoint_gain_converged": self.endpoint_gain_converged,
            "n_steps_converged": int(self.converged.shape[1]),
            "goal_error": self.goal_error,
            "goals": self.goals.tolist(),
            "goal_shifts": self.goal_shifts.tolist(),
            "endpoint_errors_fixed_horizon": self.errors_fixed.tolist(),
            "endpoint_errors_converged": self.errors_converged.tolist(),
        }


def lasa_generalisation(
    name: str = "Sshape",
    *,
    demo_index: int = 0,
    n_goals: int = 6,
    shift: float = 0.3,
    convergence_factor: int = 10,
    **dmp_params,
) -> GeneralisationResult:
    """Fit a DMP to one LASA demonstration and roll it out to shifted goals.

    The goals lie on a circle of radius ``shift × extent`` around the demonstrated goal. Each is
    reached twice: with the paper's fixed horizon (T steps; the end-point error is
    ``endpoint_gain · shift``) and run ``convergence_factor`` times longer (error → 0).
    """
    if not 0 <= demo_index < 7:
        raise ValueError(f"demo_index must be 0-6 (LASA has 7 demonstrations per shape), got {demo_index}")
    if n_goals < 1:
        raise ValueError(f"n_goals must be >= 1, got {n_goals}")
    if convergence_factor < 1:
        raise ValueError(f"convergence_factor must be >= 1, got {convergence_factor}")
    demonstration = lasa(name)[demo_index]
    dmp = DMP(**dmp_params).fit(demonstration)
    angles = np.linspace(0.0, 2.0 * np.pi, n_goals, endpoint=False)
    radius = shift * path_extent(demonstration)
    goals = demonstration[-1] + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    n_converged = convergence_factor * dmp.n_steps_
    return GeneralisationResult(
        shape=name,
        demonstration=demonstration,
        reproduction=dmp.rollout(),
        goals=goals,
        fixed_horizon=dmp.rollout_many(goals),
        converged=dmp.rollout_many(goals, n_steps=n_converged),
        endpoint_gain=dmp.endpoint_gain(),
        endpoint_gain_converged=dmp.endpoint_gain(n_converged),
        dmp_params=dmp.get_params(),
    )


# ---------------------------------------------------------------------------------------------
# Paper Table 5: G-PRM vs classic PRM
# ---------------------------------------------------------------------------------------------
BATTERY_APPROACH_VIA = ((-80.0, -120.0, 200.0), (0.0, 0.0, 40.0), (0.0, 0.0, 0.0))  # SPEC §9, mm
BATTERY_EXTENSION_TARGET = (150.0, 25.0, 0.0)  # centre of the nuts the plain DMP misses


def table5_cases() -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """The cases of ``bidmp reproduce table5``: name -> (demonstration, new target, unit).

    Four LASA shapes (demonstration 0; new target = end + (0.3, −0.2) × extent) and the battery
    approach path of SPEC §9 (T = 200) extended to (150, 25, 0) mm.
    """
    cases = {}
    for name in ("Sshape", "WShape", "NShape", "Angle"):
        y = lasa(name)[0]
        cases[f"LASA {name}"] = (y, y[-1] + np.array([0.3, -0.2]) * path_extent(y), "mm")
    battery = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    cases["battery approach"] = (battery, np.array(BATTERY_EXTENSION_TARGET), "mm")
    return cases


@dataclass
class PRMComparison:
    """G-PRM vs classic PRM on one case over many seeds (similarities per seed and iteration)."""

    name: str
    units: str
    gprm: np.ndarray  # (n_seeds, n_iter)
    prm: np.ndarray  # (n_seeds, n_iter)
    extension: ExtendedDemonstration  # seed 0, for figures
    example_prm: RoadmapResult  # seed 0, for figures

    def to_dict(self) -> dict:
        def stats(values):
            return {"mean": float(np.mean(values)), "std": float(np.std(values))}

        return {
            "case": self.name,
            "n_seeds": int(self.gprm.shape[0]),
            "gprm_per_iteration": [stats(column) for column in self.gprm.T],
            "prm_per_iteration": [stats(column) for column in self.prm.T],
            "gprm_first": stats(self.gprm[:, 0]),
            "gprm_final": stats(self.gprm.max(axis=1)),
            "prm_all": stats(self.prm),
            "prm_final": stats(self.prm.max(axis=1)),
        }


def compare_prm(y, new_target, *, name: str = "", units: str = "", n_seeds: int = 20, **options) -> PRMComparison:
    """Run G-PRM and classic PRM on the piece that :func:`extend_demonstration` imitates.

    Seeds ``0 … n_seeds − 1``; ``options`` go to :func:`extend_demonstration` (segmentation and
    roadmap options shared by both methods).
    """
    if n_seeds < 1:
        raise ValueError(f"n_seeds must be >= 1, got {n_seeds}")
    extension = extend_demonstration(y, new_target, seed=0, **options)
    roadmap_options = {k: v for k, v in options.items() if k not in ("eps_frac", "method")}
    prm_options = {k: v for k, v in roadmap_options.items() if k not in ("sigma_rel", "rho", "schedule")}
    gprm, prm, example_prm = [], [], None
    for seed in range(n_seeds):
        gprm.append(gaussian_prm(extension.tra_imi, extension.new_target, seed=seed, **roadmap_options).history)
        result = classic_prm(extension.tra_imi, extension.new_target, seed=seed, **prm_options)
        prm.append(result.history)
        example_prm = example_prm or result
    return PRMComparison(name=name, units=units, gprm=np.array(gprm), prm=np.array(prm),
                         extension=extension, example_prm=example_prm)


# ---------------------------------------------------------------------------------------------
# Paper Fig. 11: Bi-DMP on LASA shapes
# ---------------------------------------------------------------------------------------------
LASA_TARGET_OFFSETS = ((0.3, -0.2), (-0.25, -0.3), (0.15, 0.35))  # × extent, from the demonstrated end


@dataclass
class IncrementalResult:
    """One LASA shape: extended demonstrations to several targets, learned in turn by a Bi-DMP."""

    shape: str
    demonstration: np.ndarray
    targets: np.ndarray  # (P, 2)
    extensions: list  # ExtendedDemonstration per target
    bidmp_rollouts: np.ndarray  # (P, T, 2), skill="nearest"
    dmp_rollouts: np.ndarray  # (P, T, 2), the plain DMP to the same targets
    forgetting_nearest: ForgettingResult
    forgetting_latest: ForgettingResult

    def reproduction_errors(self) -> np.ndarray:
        """RMSE of each Bi-DMP rollout against its extended demonstration (mm)."""
        return np.array([
            rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
            for rollout, extension in zip(self.bidmp_rollouts, self.extensions)
        ])

    def dmp_errors(self) -> np.ndarray:
        return np.array([
            rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
            for rollout, extension in zip(self.dmp_rollouts, self.extensions)
        ])

    def to_dict(self) -> dict:
        return {
            "shape": self.shape,
            "targets": self.targets.tolist(),
            "bidmp_rmse": self.reproduction_errors().tolist(),
            "dmp_rmse": self.dmp_errors().tolist(),
            "forgetting_nearest": self.forgetting_nearest.to_dict(),
            "forgetting_latest": self.forgetting_latest.to_dict(),
        }


def lasa_incremental(name: str = "Sshape", *, seed: int = 0, offsets=LASA_TARGET_OFFSETS, **bidmp_params) -> IncrementalResult:
    """Fit a DMP to LASA demonstration 0, extend it to several new targets (1D-SEG + G-PRM) and
    learn the extensions in turn with a Bi-DMP; measure reproduction and forgetting."""
    demonstration = lasa(name)[0]
    dmp = DMP().fit(demonstration)
    targets = demonstration[-1] + np.asarray(offsets, dtype=float) * path_extent(demonstration)
    extensions = [extend_demonstration(demonstration, target, seed=seed + index) for index, target in enumerate(targets)]
    model = BiDMP(dmp, **bidmp_params)
    for extension in extensions:
        model.learn(extension.complete)
    completes = [extension.complete for extension in extensions]
    return IncrementalResult(
        shape=name,
        demonstration=demonstration,
        targets=targets,
        extensions=extensions,
        bidmp_rollouts=np.stack([model.rollout(target) for target in targets]),
        dmp_rollouts=dmp.rollout_many(targets),
        forgetting_nearest=forgetting(dmp, completes, skill="nearest", **bidmp_params),
        forgetting_latest=forgetting(dmp, completes, skill="latest", **bidmp_params),
    )
