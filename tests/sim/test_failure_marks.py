"""Failures visible in the pictures: the keyframes and the 3-D view of a failed target carried no
mark. On the kinematic arm the plain DMP misses the far nut 12 (its rollout's miss) and Bi-DMP
reaches it: the written strips are read back as pixels, the viewer's figure as its traces."""

import numpy as np
import pytest
from PIL import Image

from bidmp import tasks
from bidmp.sim import simulate, write_sim_report
from bidmp.sim.report import FAILED_COLOUR


@pytest.fixture(scope="module")
def simulated():
    nuts = tasks.load("nut-unscrewing")
    frames = {("dmp", "12"): 2, ("bidmp", "12"): 2}
    return simulate(
        nuts, ["dmp", "bidmp"], targets=["12"], backend="kinematic", frames=frames, workers=1
    )


def test_the_keyframes_of_a_failed_target_are_marked(simulated, tmp_path):
    report = simulated
    threshold = report.scenario.success_threshold
    assert not report.methods["dmp"].targets["12"].task_success(threshold)
    assert report.methods["bidmp"].targets["12"].task_success(threshold)
    write_sim_report(report, tmp_path)
    failed = np.asarray(Image.open(tmp_path / "sim_keyframes_dmp.png").convert("RGB"))
    passed = np.asarray(Image.open(tmp_path / "sim_keyframes_bidmp.png").convert("RGB"))
    # the title band (its first rows) red for the failure, white for the success, and the
    # failure's frame red along its bottom edge too
    assert tuple(failed[2, 2]) == FAILED_COLOUR and tuple(failed[-2, 10]) == FAILED_COLOUR
    assert tuple(passed[2, 2]) == (255, 255, 255)
    assert tuple(passed[-2, 10]) != FAILED_COLOUR


def test_the_3d_view_crosses_a_target_the_arm_failed(simulated):
    pytest.importorskip("plotly")
    from bidmp.plotting.viewer import add_robot_motions, layers_from_report, view_figure

    layers = add_robot_motions(layers_from_report(simulated.evaluation), simulated)
    assert "12" in layers.failures["dmp"] and "12" not in layers.failures.get("bidmp", {})
    figure = view_figure(layers)
    crossed = [trace for trace in figure.data if trace.name == "failed targets"]
    # every target a method's motion fails (the evaluation's dmp misses the far nuts), crossed
    evaluated = simulated.evaluation.methods["dmp"]
    missed = [label for label in evaluated.rollouts if not evaluated.task_success_at(label)]
    assert len(crossed) == 1 and list(crossed[0].text) == [f"{label} ✗" for label in missed]
    assert "12 ✗" in list(crossed[0].text)
    assert crossed[0].marker.symbol == "x" and "dmp:" in crossed[0].hovertext[0]
    plain = [trace for trace in figure.data if trace.name == "targets"]
    assert all(label not in list(trace.text) for trace in plain for label in missed)


def test_the_3d_view_of_an_all_green_run_has_no_cross(simulated):
    pytest.importorskip("plotly")
    from bidmp.plotting.viewer import layers_from_report, view_figure

    layers = layers_from_report(simulated.evaluation)
    layers.failures = {}
    names = [trace.name for trace in view_figure(layers).data]
    assert "failed targets" not in names and "targets" in names
