"""Paper Fig. 11: Bi-DMP on LASA shapes, skills learned one after another to moved targets,
with the forgetting of the earlier ones measured."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._checks import as_points, check_int
from .._trajectory import path_extent, resample_time, rmse
from ..demonstrations.datasets import lasa
from ..extension.extend import extend_demonstration
from ..incremental.bidmp import BiDMP, ForgettingResult, forgetting_runs
from ..primitives.dmp import DMP
from ..tasks._tables import markdown_table, text_table

__all__ = [
    "LASA_TARGET_OFFSETS",
    "FIGURE_SHAPES",
    "IncrementalResult",
    "lasa_incremental",
    "Figures",
    "run_figures",
]


# ---------------------------------------------------------------------------------------------
# Paper Fig. 11: Bi-DMP on LASA shapes
# ---------------------------------------------------------------------------------------------
# × extent, from the demonstrated end
LASA_TARGET_OFFSETS = (
    (0.3, -0.2),
    (-0.25, -0.3),
    (0.15, 0.35),
)


FIGURE_SHAPES = ("Sshape", "WShape", "NShape")


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
        return np.array(
            [
                rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
                for rollout, extension in zip(self.bidmp_rollouts, self.extensions)
            ]
        )

    def dmp_errors(self) -> np.ndarray:
        return np.array(
            [
                rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
                for rollout, extension in zip(self.dmp_rollouts, self.extensions)
            ]
        )

    def to_dict(self) -> dict:
        return {
            "shape": self.shape,
            "targets": self.targets.tolist(),
            "bidmp_rmse": self.reproduction_errors().tolist(),
            "dmp_rmse": self.dmp_errors().tolist(),
            "forgetting_nearest": self.forgetting_nearest.to_dict(),
            "forgetting_latest": self.forgetting_latest.to_dict(),
        }


def lasa_incremental(
    name: str = "Sshape", *, seed: int = 0, offsets=LASA_TARGET_OFFSETS, **bidmp_params
) -> IncrementalResult:
    """Fit a DMP to LASA demonstration 0, extend it to several new targets (1D-SEG + G-PRM) and
    learn the extensions in turn with a Bi-DMP; measure reproduction and forgetting (one
    learning pass: the forgetting measurement learns into the model that is then rolled out)."""
    demonstration = lasa(name)[0]
    offsets = as_points(offsets, 2, "offsets")
    check_int(offsets.shape[0], "the number of offsets", limit="max_targets")
    seed = check_int(seed, "seed", minimum=0, maximum=2**32)
    dmp = DMP(protocol="paper").fit(demonstration)
    targets = demonstration[-1] + offsets * path_extent(demonstration)
    extensions = [
        extend_demonstration(demonstration, target, seed=seed + index, approach="paper")
        for index, target in enumerate(targets)
    ]
    model = BiDMP(dmp, **bidmp_params)
    runs = forgetting_runs(
        model, [extension.complete for extension in extensions], ("nearest", "latest")
    )
    return IncrementalResult(
        shape=name,
        demonstration=demonstration,
        targets=targets,
        extensions=extensions,
        bidmp_rollouts=np.stack([model.rollout(target) for target in targets]),
        dmp_rollouts=dmp.rollout_many(targets),
        forgetting_nearest=runs["nearest"],
        forgetting_latest=runs["latest"],
    )


@dataclass
class Figures:
    """Fig. 11 analogue: :class:`IncrementalResult` per shape."""

    results: list[IncrementalResult]

    def rows(self) -> tuple[list[str], list[list[str]]]:
        header = [
            "shape",
            "skill",
            "Bi-DMP RMSE",
            "plain DMP RMSE",
            "forgetting nearest",
            "forgetting latest",
        ]
        rows = []
        for result in self.results:
            for index, (bidmp_error, dmp_error) in enumerate(
                zip(result.reproduction_errors(), result.dmp_errors()), start=1
            ):
                rows.append(
                    [
                        result.shape,
                        str(index),
                        f"{bidmp_error:.3f}",
                        f"{dmp_error:.1f}",
                        f"{result.forgetting_nearest.forgetting[index]:.3f}",
                        f"{result.forgetting_latest.forgetting[index]:.1f}",
                    ]
                )
            rows.append(
                [
                    result.shape,
                    "0 (demo)",
                    "-",
                    "-",
                    f"{result.forgetting_nearest.forgetting[0]:.3f}",
                    f"{result.forgetting_latest.forgetting[0]:.1f}",
                ]
            )
        return header, rows

    def to_dict(self) -> dict:
        return {"results": [result.to_dict() for result in self.results]}

    def summary(self) -> str:
        return (
            "Bi-DMP on LASA shapes: three extended demonstrations learned in turn (errors in mm)\n"
            + text_table(*self.rows())
            + "\nforgetting = error of a skill after all learning minus its error when it was learned"
        )

    def markdown(self) -> str:
        return markdown_table(*self.rows())


def run_figures(shapes=FIGURE_SHAPES, progress: Callable | None = None) -> Figures:
    """:func:`lasa_incremental` on each shape. ``progress`` wraps the shape iterator."""
    iterator = progress(shapes) if progress is not None else shapes
    return Figures([lasa_incremental(name) for name in iterator])


# ---------------------------------------------------------------------------------------------
# Paper Tables 1, 2 and 4: the battery case studies
# ---------------------------------------------------------------------------------------------
