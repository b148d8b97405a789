"""Paper Table 5: G-PRM against the classic PRM on the paper's cases, over many seeds."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._checks import check_int
from .._trajectory import path_extent
from ..demonstrations.datasets import lasa, minimum_jerk
from ..extension.extend import ExtendedDemonstration, extend_demonstration
from ..extension.roadmap import RoadmapOptions, RoadmapResult, classic_prm, gaussian_prm
from ..tasks._tables import markdown_table, text_table

__all__ = [
    "MAX_SEEDS",
    "BATTERY_APPROACH_VIA",
    "BATTERY_EXTENSION_TARGET",
    "table5_cases",
    "PRMComparison",
    "compare_prm",
    "Table5",
    "run_table5",
]


MAX_SEEDS = 200  # seeds of one G-PRM vs PRM comparison (each runs both roadmaps, ~30 ms a seed)


# ---------------------------------------------------------------------------------------------
# Paper Table 5: G-PRM vs classic PRM
# ---------------------------------------------------------------------------------------------
# mm, the paper's battery approach
BATTERY_APPROACH_VIA = (
    (-80.0, -120.0, 200.0),
    (0.0, 0.0, 40.0),
    (0.0, 0.0, 0.0),
)


BATTERY_EXTENSION_TARGET = (150.0, 25.0, 0.0)  # centre of the nuts the plain DMP misses


def table5_cases() -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """The cases of ``bidmp reproduce table5``: name -> (demonstration, new target, unit).

    Four LASA shapes (demonstration 0; new target = end + (0.3, −0.2) × extent) and the battery
    battery approach path (T = 200) extended to (150, 25, 0) mm.
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


def compare_prm(  # noqa: PLR0913 - the experiment's options, each one
    y,
    new_target,
    *,
    name: str = "",
    units: str = "",
    n_seeds: int = 20,
    roadmap: RoadmapOptions | None = None,
    eps_frac: float = 0.1,
    method: str = "persistence",
) -> PRMComparison:
    """Run G-PRM and classic PRM on the piece that :func:`extend_demonstration` imitates.

    Seeds ``0 … n_seeds − 1``; ``eps_frac`` and ``method`` segment the demonstration, ``roadmap``
    (default ``RoadmapOptions()``) is shared by both roadmaps (G-PRM's ``sigma_rel``, ``rho`` and
    ``schedule`` are its own).
    """
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1, maximum=MAX_SEEDS)
    roadmap = RoadmapOptions() if roadmap is None else roadmap
    extension = extend_demonstration(
        y, new_target, seed=0, approach="paper", roadmap=roadmap, eps_frac=eps_frac, method=method
    )
    gprm, prm, example_prm = [], [], None
    for seed in range(n_seeds):
        if seed == 0 and len(extension.similarity_history):
            gprm.append(extension.similarity_history)  # the extension already ran G-PRM with seed 0
        else:
            gprm.append(
                gaussian_prm(extension.tra_imi, extension.new_target, roadmap, seed=seed).history
            )
        result = classic_prm(extension.tra_imi, extension.new_target, roadmap, seed=seed)
        prm.append(result.history)
        example_prm = example_prm or result
    return PRMComparison(
        name=name,
        units=units,
        gprm=np.array(gprm),
        prm=np.array(prm),
        extension=extension,
        example_prm=example_prm,
    )


@dataclass
class Table5:
    """All Table 5 cases."""

    comparisons: list[PRMComparison]
    n_seeds: int

    def rows(self) -> tuple[list[str], list[list[str]]]:
        n_iter = self.comparisons[0].gprm.shape[1]
        header = ["case", "method"] + [f"it {i}" for i in range(1, n_iter + 1)] + ["best-of"]
        rows = []
        for comparison in self.comparisons:
            for label, data in (("G-PRM", comparison.gprm), ("PRM", comparison.prm)):
                best = data.max(axis=1)
                rows.append(
                    [comparison.name, label]
                    + [f"{m:.3f}±{sd:.3f}" for m, sd in zip(data.mean(axis=0), data.std(axis=0))]
                    + [f"{best.mean():.3f}±{best.std():.3f}"]
                )
        return header, rows

    def compact_rows(self) -> tuple[list[str], list[list[str]]]:
        """The README's columns: G-PRM first/last/best-of, classic PRM all iterations/best-of."""
        header = [
            "case",
            "G-PRM it 1",
            f"G-PRM it {self.comparisons[0].gprm.shape[1]}",
            "G-PRM best-of",
            "classic PRM (all iterations)",
            "classic PRM best-of",
        ]

        def cell(values):
            return f"{np.mean(values):.3f} ± {np.std(values):.3f}"

        rows = [
            [
                c.name,
                cell(c.gprm[:, 0]),
                cell(c.gprm[:, -1]),
                cell(c.gprm.max(axis=1)),
                cell(c.prm),
                cell(c.prm.max(axis=1)),
            ]
            for c in self.comparisons
        ]
        return header, rows

    def to_dict(self) -> dict:
        return {
            "table": "5",
            "n_seeds": self.n_seeds,
            "cases": [c.to_dict() for c in self.comparisons],
        }

    def summary(self) -> str:
        return (
            f"Table 5 analogue: Fréchet similarity of the generated path, mean ± std over {self.n_seeds} seeds\n"
            + text_table(*self.rows())
        )

    def markdown(self) -> str:
        return markdown_table(*self.compact_rows())


def run_table5(n_seeds: int = 20, progress: Callable | None = None) -> Table5:
    """G-PRM vs classic PRM on every case of :func:`table5_cases`. ``progress`` wraps the case
    iterator (e.g. ``tqdm``)."""
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1, maximum=MAX_SEEDS)
    cases = table5_cases().items()
    iterator = progress(cases) if progress is not None else cases
    return Table5(
        [
            compare_prm(y, target, name=name, units=units, n_seeds=n_seeds)
            for name, (y, target, units) in iterator
        ],
        n_seeds,
    )
