"""The evaluation's figures in any unit: one random cell evaluated in millimetres and in metres.
A metre cell drew 16 m discs on ±20 m axes and an error axis whose ticks read 0 (its sizes were
millimetre numbers, its errors 0.001 of the axis). The figures are inspected as matplotlib objects
(the discs, the limits, the lines' data and the ticks' text), the numbers checked against the
reports' own errors converted by hand."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tasks"))
from test_random_cells import random_cell  # noqa: E402

from bidmp.tasks import evaluate, scenarios  # noqa: E402

pytest.importorskip("matplotlib")


def in_unit(spec: dict, unit: str) -> dict:
    """A random cell's dict with every length in ``unit`` (the keys random_cell writes)."""
    factor = {"mm": 1.0, "m": 1e-3}[unit] / {"mm": 1.0, "m": 1e-3}[spec["units"]]
    scale = lambda values: (np.asarray(values, dtype=float) * factor).tolist()  # noqa: E731
    out = {**spec, "units": unit, "name": f"{spec['name']}-{unit}"}
    out["targets"] = {label: scale(point) for label, point in spec["targets"].items()}
    out["demonstration"] = {"points": scale(spec["demonstration"]["points"])}
    out["success_threshold"] = spec["success_threshold"] * factor
    out["approach_height"] = spec["approach_height"] * factor
    scene = spec["scene"]
    parts = []
    for part in scene["parts"]:
        part = dict(part)
        for key in ("at", "size", "offset"):
            if key in part:
                part[key] = scale(part[key])
        for key in ("radius", "height"):
            if key in part:
                part[key] = part[key] * factor
        parts.append(part)
    out["scene"] = {
        **scene,
        "tool": {key: value * factor for key, value in scene["tool"].items()},
        "margin": scene["margin"] * factor,
        "parts": parts,
    }
    return out


@pytest.fixture(scope="module")
def reports():
    spec = random_cell(4)
    return {
        unit: evaluate(scenarios.from_dict(in_unit(spec, unit)), ["dmp", "bidmp"])
        for unit in ("mm", "m")
    }


@pytest.fixture
def figures(monkeypatch):
    """The figures the plotting functions make, kept open instead of written."""
    from bidmp.plotting import tasks

    made = []
    monkeypatch.setattr(tasks, "_save", lambda fig, path: made.append(fig) or Path(path))
    yield made
    import matplotlib.pyplot as plt

    for fig in made:
        plt.close(fig)


def test_the_top_view_is_the_same_picture_in_mm_and_in_m(reports, figures, tmp_path):
    from matplotlib.patches import Circle

    from bidmp.plotting import plot_targets_top_view

    shares = {}
    for unit, report in reports.items():
        plot_targets_top_view(tmp_path / f"top_{unit}.png", report)
        ax = figures[-1].axes[0]
        discs = [patch for patch in ax.patches if isinstance(patch, Circle)]
        assert len(discs) == len(report.scenario.targets)
        width = np.diff(ax.get_xlim())[0]
        shares[unit] = (discs[0].get_radius() / width, ax.get_xlim()[0] / width)
        # the discs do not overlap: each less than half the nearest two targets' distance
        xy = report.scenario.target_array[:, :2]
        gaps = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
        assert discs[0].get_radius() < 0.5 * gaps[gaps > 0].min()
        # the axes hold the targets, not ±20 of the unit round them
        assert width < 3.0 * np.ptp(xy[:, 0]) + 1e-12
        labels = [tick.get_text() for tick in ax.get_xticklabels()]
        assert len(set(labels)) == len(labels) > 2, labels
    np.testing.assert_allclose(shares["m"], shares["mm"], rtol=1e-6)


def test_the_error_plot_reads_in_mm_with_the_thresholds_value(reports, figures, tmp_path):
    from bidmp.plotting import plot_error_vs_distance

    for unit, report in reports.items():
        plot_error_vs_distance(tmp_path / f"err_{unit}.png", report)
        ax = figures[-1].axes[0]
        threshold = [line for line in ax.lines if line.get_label().startswith("threshold")]
        assert len(threshold) == 1
        assert threshold[0].get_label() == "threshold 1.75 mm"
        np.testing.assert_allclose(threshold[0].get_ydata(), 1.75, rtol=1e-12)
        assert ax.get_ylabel() == "end-point error [mm]"
        to_mm = {"mm": 1.0, "m": 1e3}[unit]
        for line in ax.lines:
            name = line.get_label()
            if name in report.methods:
                expected = sorted(report.methods[name].errors.values())
                np.testing.assert_allclose(
                    np.sort(np.asarray(line.get_ydata())), np.asarray(expected) * to_mm, rtol=1e-12
                )
        figures[-1].canvas.draw()
        ticks = [tick.get_text() for tick in ax.get_yticklabels() if tick.get_text()]
        assert len(ticks) >= 3 and "1" in ticks, ticks
