"""The LASA fit-and-generalise example: a DMP fitted on a LASA shape, reproduced and rolled out
to moved goals, with the fixed horizon's end-point error against a converged run."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import check_int, check_real
from .._trajectory import path_extent, rmse
from ..demonstrations.datasets import lasa
from ..primitives.dmp import DMP
from ..tasks._tables import text_table

__all__ = ["GeneralisationResult", "lasa_generalisation"]


# ---------------------------------------------------------------------------------------------
# LASA fit-and-generalise example (bidmp demo --lasa)
# ---------------------------------------------------------------------------------------------
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

    def summary(self) -> str:
        data = self.to_dict()
        rows = [
            [
                str(i + 1),
                f"{shift:.2f}",
                f"{fixed:.3f}",
                f"{self.endpoint_gain * shift:.3f}",
                f"{conv:.2e}",
            ]
            for i, (shift, fixed, conv) in enumerate(
                zip(self.goal_shifts, self.errors_fixed, self.errors_converged)
            )
        ]
        return "\n".join(
            [
                f"one LASA '{self.shape}' demonstration ({data['n_samples']} samples, 2-D), DMP with defaults",
                f"  reproduction RMSE {data['reproduction_rmse']:.3f} mm = "
                f"{data['reproduction_rmse_percent']:.2f} % of the extent",
                f"  end-point gain c = {self.endpoint_gain:.4f} after T steps, "
                f"{self.endpoint_gain_converged:.2e} after "
                f"{data['n_steps_converged']} steps",
                f"  end-point error at the demonstrated goal after T steps: e0 = {self.goal_error:.3f} mm",
                "",
                text_table(
                    [
                        "goal",
                        "shift [mm]",
                        "error, T steps",
                        "c * shift",
                        f"error, {data['n_steps_converged']} steps",
                    ],
                    rows,
                ),
                "",
                "Stopped after the demonstration's T steps (the paper's protocol), a DMP misses a moved goal by",
                "c * shift on top of e0 (the error vector is e0 + (B - 1) * shift, exactly); run to convergence it",
                "reaches every goal.",
            ]
        )


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
    # LASA has 7 demonstrations per shape
    demo_index = check_int(demo_index, "demo_index", minimum=0, maximum=6)
    n_goals = check_int(n_goals, "n_goals", minimum=1, limit="max_targets")
    convergence_factor = check_int(
        convergence_factor, "convergence_factor", minimum=1, maximum=1000
    )
    shift = check_real(shift, "shift", nonnegative=True, maximum=1e3)
    demonstration = lasa(name)[demo_index]
    dmp = DMP(**{"protocol": "paper", **dmp_params}).fit(demonstration)
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
