"""The 3-D viewer: meshes of the scene's solids against closed forms, every layer in
the file, the robot's motion from its base to the target, round trips, bad files, the CLI."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("plotly")

from bidmp.cli import main  # noqa: E402
from bidmp.plotting import viewer  # noqa: E402
from bidmp.tasks import evaluate, scenarios  # noqa: E402


def hull_volume(vertices, faces):
    """Volume enclosed by a closed triangle mesh (divergence theorem, about its centroid)."""
    centre = vertices.mean(axis=0)
    a, b, c = (vertices[faces[:, k]] - centre for k in range(3))
    return float(np.abs(np.einsum("ij,ij->i", a, np.cross(b, c))).sum() / 6.0)


def rotation(seed):
    from scipy.spatial.transform import Rotation

    return Rotation.random(random_state=seed).as_matrix()


@pytest.mark.parametrize("seed", range(5))
def test_solid_meshes_enclose_the_solids_volume(seed):
    rng = np.random.default_rng(seed)
    turn, centre = rotation(seed), rng.uniform(-100, 100, 3)
    size = rng.uniform(1, 50, 3)
    vertices, faces = viewer.solid_mesh("box", centre, turn, size)
    assert hull_volume(vertices, faces) == pytest.approx(np.prod(size), rel=1e-9)
    radius, height, sides = rng.uniform(1, 20), rng.uniform(1, 40), 24
    vertices, faces = viewer.solid_mesh("cylinder", centre, turn, (radius, height), sides=sides)
    polygon = 0.5 * sides * radius**2 * math.sin(2 * math.pi / sides)  # the inscribed 24-gon's area
    assert hull_volume(vertices, faces) == pytest.approx(polygon * height, rel=1e-9)
    # The cylinder's axis is the rotation's z: every vertex at its radius from that axis.
    offset = vertices - centre
    along = offset @ turn[:, 2]
    np.testing.assert_allclose(np.linalg.norm(offset - np.outer(along, turn[:, 2]), axis=1), radius)
    np.testing.assert_allclose(np.abs(along), height / 2)


def test_an_unknown_solid_kind_is_named():
    with pytest.raises(
        ValueError, match="kind must be one of 'box', 'cylinder', 'convex'; got 'sphere'"
    ):
        viewer.solid_mesh("sphere", [0, 0, 0], np.eye(3), (1.0,))


@pytest.fixture(scope="module")
def nut_layers():
    pytest.importorskip("pybullet")
    from bidmp import sim

    nut = scenarios.load("nut-unscrewing")
    report = sim.execution_report(nut, ["dmp", "bidmp"])
    result = sim.simulate(
        nut, ["bidmp"], targets=["11"], report=report, workers=1, views=[("bidmp", "11")]
    )
    return nut, viewer.add_robot_motions(viewer.layers_from_report(report), result)


def test_the_viewer_holds_every_layer(nut_layers, tmp_path):
    nut, layers = nut_layers
    assert len(layers.segmentation) >= 1 and len(layers.extended) >= 1
    assert set(layers.rollouts) == {"dmp", "bidmp"} and set(layers.rollouts["bidmp"]) == set(
        nut.targets
    )
    assert len(layers.solids) == len(nut.scene.solids)
    figure = viewer.view_figure(layers)
    names = {trace.name for trace in figure.data}
    assert names - {None} == {
        "demonstration",
        "segmentation points",
        "extended demonstrations",
        "dmp rollouts",
        "dmp: breaks the contract",
        "bidmp rollouts",
        "targets",
        "failed targets",
        "scene parts",
        "robot (joint to joint)",
    }  # the DMP misses the far nuts: drawn as failing, the nuts crossed
    assert len(figure.frames) == len(layers.robot["bidmp -> 11"]["times"])
    assert len(figure.layout.sliders[0].steps) == len(figure.frames)
    page = viewer.write_view(tmp_path / "view.html", layers)
    text = page.read_text()
    assert (
        "plotly.js v" in text and '<script src="http' not in text
    )  # plotly.js inside: opens offline
    for name in names - {None}:
        assert json.dumps(name) in text


def test_the_robot_moves_from_its_base_to_the_target(nut_layers):
    """Independent anchors: the first joint origin is the scenario's robot base, and the tool's
    mouth (the last point) ends on the target within the task's threshold."""
    nut, layers = nut_layers
    motion = layers.robot["bidmp -> 11"]
    links, times = motion["links"], motion["times"]
    base = np.asarray(nut.robot.base, dtype=float)
    np.testing.assert_allclose(links[:, 0], np.broadcast_to(base, links[:, 0].shape), atol=1e-6)
    assert np.linalg.norm(links[-1, -1] - nut.targets["11"]) <= nut.success_threshold
    assert np.all(np.diff(times) > 0) and times[-1] > 1.0
    # Joints move continuously: no link jumps more than 40 ms at 2 m/s would carry it.
    assert np.max(np.linalg.norm(np.diff(links, axis=0), axis=2)) <= 2000.0 * 0.04 + 1e-9


def test_layers_round_trip_and_bad_files_are_named(nut_layers, tmp_path):
    _, layers = nut_layers
    path = viewer.save_layers(tmp_path / "view_layers.npz", layers)
    back = viewer.load_layers(path)
    np.testing.assert_array_equal(back.demonstration, layers.demonstration)
    np.testing.assert_array_equal(
        back.robot["bidmp -> 11"]["links"], layers.robot["bidmp -> 11"]["links"]
    )
    assert back.solids == layers.solids and back.rollouts.keys() == layers.rollouts.keys()
    for method in layers.rollouts:
        for label, path_ in layers.rollouts[method].items():
            np.testing.assert_array_equal(back.rollouts[method][label], path_)
    broken = tmp_path / "broken.npz"
    broken.write_bytes(path.read_bytes()[:300])
    with pytest.raises(ValueError, match="broken.npz: cannot read a bidmp view"):
        viewer.load_layers(broken)
    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, meta=np.frombuffer(json.dumps({"kind": "other"}).encode(), dtype=np.uint8))
    with pytest.raises(ValueError, match="not a bidmp view file"):
        viewer.load_layers(foreign)


def test_bidmp_demo_view_and_bidmp_view(tmp_path, capsys):
    assert main(["demo", "--methods", "dmp,bidmp", "--view", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "view.html").stat().st_size > 3_000_000  # plotly.js is inside
    (tmp_path / "view.html").unlink()
    assert main(["view", str(tmp_path)]) == 0
    assert (tmp_path / "view.html").is_file()
    capsys.readouterr()
    assert main(["view", str(tmp_path / "nothing")]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds no view_layers.npz" in err and "\n" not in err


def test_every_3d_figure_has_one_scale_on_its_three_axes():
    """Structure guard: a 300 mm move along x with micrometre noise along z is drawn in a cube
    (equal spans, equal box sides), not with z stretched to fill the figure."""
    from bidmp.plotting._base import _figure, _label_axes

    rng = np.random.default_rng(0)
    path = np.column_stack(
        [np.linspace(0.0, 300.0, 50), np.linspace(0.0, 40.0, 50), 5.0 + 1e-3 * rng.normal(size=50)]
    )
    _, _, ax = _figure(True)  # a Figure without pyplot: nothing to close
    ax.plot(*path.T)
    _label_axes(ax, 3, "mm")
    spans = [np.ptp(limits) for limits in (ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d())]
    assert spans[0] >= 300.0 and np.allclose(spans, spans[0])
    np.testing.assert_allclose(ax.get_box_aspect() / ax.get_box_aspect()[0], 1.0)


@pytest.fixture(scope="module")
def posts_report():
    """The nut task with two 4 mm posts among the nuts: the plain DMP drives into them on its way
    to four nuts (tests/tasks/test_user_cells.py checks that by closed-form geometry)."""
    data = json.loads((Path(__file__).parents[1] / "data" / "two_posts.json").read_text())
    return data, evaluate(scenarios.from_dict(data), ["dmp", "bidmp"])


def test_a_failing_motion_is_drawn_in_amber_with_the_part_it_came_too_close_to(
    posts_report, tmp_path
):
    """Independent anchor: the point each failure names lies within the tool's radius
    plus the margin of the post it names (a vertical cylinder of the spec, measured here)."""
    data, report = posts_report
    layers = viewer.layers_from_report(report)
    dmp = report.methods["dmp"]
    assert set(layers.failures["dmp"]) == {
        label for label in dmp.rollouts if not dmp.task_success_at(label)
    }
    assert "bidmp" not in layers.failures  # every Bi-DMP motion keeps the contract here
    posts = {
        part["label"]: part for part in data["scene"]["parts"] if part.get("type") == "cylinder"
    }
    reach = data["scene"]["tool"]["radius"] + data["scene"]["margin"]
    near_posts = {
        label: failure
        for label, failure in layers.failures["dmp"].items()
        if failure["part"] in posts
    }
    assert len(near_posts) >= 2
    for label, failure in near_posts.items():
        post = posts[failure["part"]]
        horizontal = np.hypot(
            failure["point"][0] - post["at"][0], failure["point"][1] - post["at"][1]
        )
        assert horizontal <= post["radius"] + reach + 1e-6, (label, failure)
        assert failure["reason"]
    figure = viewer.view_figure(layers)
    amber = [
        trace
        for trace in figure.data
        if getattr(trace, "line", None) is not None and trace.line.color == viewer.WARNING
    ]
    assert len(amber) == len(layers.failures["dmp"]) and all(
        trace.line.dash == "dash" for trace in amber
    )
    meshes = {
        trace.hovertext.split(":")[0]: trace.color
        for trace in figure.data
        if trace.type == "mesh3d"
    }
    for failure in near_posts.values():
        assert meshes[failure["part"]] == viewer.WARNING
    assert meshes["plate"] != viewer.WARNING or any(
        f["part"] == "plate" for f in layers.failures["dmp"].values()
    )
    back = viewer.load_layers(viewer.save_layers(tmp_path / "v.npz", layers))
    assert back.failures == json.loads(json.dumps(layers.failures))


def test_the_scenario_figure_draws_every_judged_rollout_and_the_parts_as_solids(
    posts_report, tmp_path
):
    """each collision mark belongs to a drawn rollout (before, the marks of GMM's
    rollouts floated where no drawn path went) and every part is a shaded solid."""
    import matplotlib

    matplotlib.use("Agg")
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from bidmp.plotting import tasks

    _, report = posts_report
    captured = {}
    original = tasks._save
    tasks._save = lambda fig, path: captured.setdefault("fig", fig) and original(fig, path)
    try:
        tasks.plot_scenario_3d(tmp_path / "s.png", report)
    finally:
        tasks._save = original
    ax = captured["fig"].axes[0]
    paths = [line for line in ax.get_lines() if len(line.get_data_3d()[0]) > 1]
    drawn = {tuple(np.round(np.column_stack(line.get_data_3d())[-1], 6)) for line in paths}
    for result in report.methods.values():
        for rollout in result.rollouts.values():
            assert tuple(np.round(rollout[-1, :3], 6)) in drawn
    marks = [line for line in ax.get_lines() if line.get_marker() == "X"]
    failing = [
        (name, label)
        for name, result in report.methods.items()
        for label in result.rollouts
        if not result.task_success_at(label)
        and result.clearance_at(label) is not None
        and not result.clearance_at(label).clear
    ]
    assert len(marks) == len(failing) >= 2
    solids = [c for c in ax.collections if isinstance(c, Poly3DCollection)]
    assert len(solids) == len(report.scenario.scene.solids)


def test_the_pose_plot_shows_the_orientation_turn_and_tilt():
    """against closed forms: a tool turning 540 degrees about its own axis while that
    axis tilts by 20 degrees about x reads 540 (unwrapped) and 20."""
    from scipy.spatial.transform import Rotation

    from bidmp.plotting.trajectories import _tool_angles

    s = np.linspace(0.0, 1.0, 301)
    turn, tilt = np.radians(540.0) * s, np.radians(20.0) * s
    start = Rotation.from_euler("x", 180, degrees=True)  # the tool pointing down
    rotations = (
        start * Rotation.from_euler("x", tilt[:, None]) * Rotation.from_euler("z", turn[:, None])
    )
    measured_turn, measured_tilt = _tool_angles(rotations.as_quat())
    np.testing.assert_allclose(measured_turn, np.degrees(turn), atol=1e-9)
    np.testing.assert_allclose(measured_tilt, np.degrees(tilt), atol=1e-6)


def test_a_two_line_title_renders_as_two_lines_and_control_codes_do_not(tmp_path):
    """Found looking at the extension figure: its second title line ('G-PRM similarity ...') was
    drawn after a '?' in place of the line break."""
    import matplotlib

    matplotlib.use("Agg")
    from bidmp.demonstrations import minimum_jerk
    from bidmp.extension import extend_demonstration
    from bidmp.plotting import extension as figures

    demo = minimum_jerk(np.array([[0.0, 0.0, 60.0], [80.0, 0.0, 60.0], [80.0, 0.0, 0.0]]), 200)
    extended = extend_demonstration(demo, [160.0, 40.0, 0.0])
    captured = {}
    original = figures._save
    figures._save = lambda fig, path: captured.setdefault("fig", fig) and original(fig, path)
    try:
        figures.plot_extension(tmp_path / "e.png", extended, units="mm", title="run \x1b[31m7")
    finally:
        figures._save = original
    title = captured["fig"].axes[0].get_title()
    first, second = title.split("\n")
    assert first == "run ?[31m7" and second.startswith("G-PRM similarity ")


def test_the_spread_of_several_demonstration_methods_is_a_band_round_their_rollouts(tmp_path):
    """The band's radius is twice the norm of the model's own standard deviation along the
    rollout (the DMP from several demonstrations: exact; the ProMP: conditioned on the rollout's
    start and goal, so 0 at both ends); the tube's vertices lie that far from the path; the
    layers keep it through their file."""
    from bidmp.plotting.viewer import (
        _tube,
        layers_from_report,
        load_layers,
        save_layers,
        view_figure,
    )
    from bidmp.tasks import evaluate, scenarios

    report = evaluate(scenarios.load("nut-unscrewing"), ["promp", "dmp-multi"], geometry=False)
    layers = layers_from_report(report)
    multi = report.fitted["dmp-multi"]
    rollout = report.methods["dmp-multi"].rollouts["12"]
    expected = 2 * np.linalg.norm(multi.std(rollout[-1], n_steps=len(rollout)), axis=1)
    np.testing.assert_allclose(layers.bands["dmp-multi"]["12"], expected)
    promp_band = layers.bands["promp"]["1"]
    assert promp_band[0] < 1e-6 * promp_band.max() and promp_band[-1] < 1e-6 * promp_band.max()
    path = np.asarray(report.methods["promp"].rollouts["1"], dtype=float)
    vertices, faces = _tube(path, promp_band, sides=8)
    distances = np.linalg.norm(vertices.reshape(len(path), 8, 3) - path[:, None], axis=2)
    np.testing.assert_allclose(distances, np.repeat(promp_band[:, None], 8, 1), atol=1e-9)
    names = {trace.name for trace in view_figure(layers).data}
    assert {"promp ±2σ band", "dmp-multi ±2σ band"} <= names
    loaded = load_layers(save_layers(tmp_path / "bands.npz", layers))
    np.testing.assert_array_equal(loaded.bands["promp"]["1"], promp_band)
