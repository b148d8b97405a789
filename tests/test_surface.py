"""The public surface refuses bad input at its boundary: a
TypeError/ValueError naming the argument, in one short line, before any work or allocation; never
an internal error, a silent NaN, a leaked warning or NumPy's own text. Each case failed before."""

import warnings

import numpy as np
import pytest

import bidmp
from bidmp.demonstrations.datasets import lasa
from bidmp.extension.segmentation import curvature
from bidmp.primitives.canonical import phase_grid
from bidmp.primitives.forcing import kernel_centres

DEMO = np.linspace([0.0, 0.0], [1.0, 2.0], 50) + np.sin(np.linspace(0, 3, 50))[:, None]


@pytest.fixture(autouse=True)
def no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def refused(error, match, function, *args, **kwargs):
    with pytest.raises(error, match=match) as info:
        function(*args, **kwargs)
    message = str(info.value)
    assert "\n" not in message and len(message) <= 300, message
    return message


@pytest.fixture(scope="module")
def dmp():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return bidmp.DMP().fit(DEMO)


def test_a_trajectory_without_times_is_a_type_error():
    rows = np.zeros((3, 2))
    refused(
        TypeError,
        r"Trajectory\.t must be an array of numbers, got None",
        bidmp.Trajectory,
        None,
        rows,
        rows,
        rows,
    )
    refused(
        ValueError,
        r"Trajectory\.yd must have shape \(3, D\)",
        bidmp.Trajectory,
        np.arange(3.0),
        rows,
        rows[:2],
        rows,
    )


def test_a_phase_outside_the_dmps_range_is_refused_not_overflowed(dmp):
    refused(ValueError, r"phase must lie in \[0, 1\]", dmp.basis, [-1.0])
    refused(ValueError, r"phase contains NaN", dmp.forcing_term, [0.5, np.nan])
    assert np.all(np.isfinite(dmp.forcing_term([0.0, 0.3, 1.0])))


def test_messages_name_the_argument_and_quote_at_most_ten_characters(dmp):
    message = refused(ValueError, r"set_params: unknown parameter 'bogus'", dmp.set_params, bogus=1)
    assert "alpha_phase" in message
    refused(ValueError, r"unknown parameter 'xxxxxxxxxx…'", dmp.set_params, **{"x" * 5000: 1})
    refused(
        TypeError,
        r"forcing_increment must be callable",
        dmp.rollout,
        forcing_increment=np.zeros((3, 2)),
    )
    refused(ValueError, r"unknown LASA shape 'xxxxxxxxxx…'", lasa, "x" * 10000)


def test_sizes_are_bounded_before_anything_is_allocated():
    refused(
        ValueError,
        r"n_steps = 2,147,483,648 exceeds the limit max_steps",
        phase_grid,
        2**31,
        1e-9,
        exact=True,
    )
    refused(
        ValueError,
        r"n_kernels = 2,147,483,648 exceeds the limit max_kernels",
        kernel_centres,
        2**31,
        100,
        0.01,
    )


def test_complex_input_is_refused_not_truncated(dmp):
    refused(TypeError, r"y must be real numbers", curvature, DEMO + 1j)
    refused(TypeError, r"y must be real numbers", bidmp.DMP().fit, DEMO.astype(complex))
    model = bidmp.BiDMP(dmp)
    refused(
        TypeError,
        r"forcing_increment must be real numbers",
        model.learn_increment,
        np.zeros((dmp.n_train_, 2)) + 1j,
        [1.0, 2.0],
    )


def test_loops_and_sizes_are_bounded_where_a_caller_chooses_them(peak_memory):
    """The fuzz campaign's hangs: an ADMM run of 10**7 iterations, a reference Fréchet over 1e8 cells,
    a 5e8-row extent: refused up front, in one line."""
    from bidmp.extension.similarity import frechet_distance_reference
    from bidmp.incremental.linalg import sparse_autoencoder
    from bidmp.tasks import path_extent

    rng = np.random.default_rng(0)
    F, target = rng.normal(size=(30, 5)), rng.normal(size=(30, 2))
    with peak_memory() as peak:
        refused(
            ValueError,
            r"n_iter must be <= 10,000, got 10,000,000",
            sparse_autoencoder,
            F,
            target,
            1e-3,
            10**7,
        )
        refused(ValueError, r"target must have 30 rows", sparse_autoencoder, F, target[:5])
        long = np.zeros((10_001, 2))
        refused(ValueError, r"use frechet_distance", frechet_distance_reference, long, long)
        refused(
            ValueError,
            r"over the limit max_array_bytes",
            path_extent,
            np.broadcast_to(np.zeros(2), (500_000_000, 2)),
        )
    assert peak.megabytes < 20.0, peak.megabytes  # refused before the work (the extent: 8 GB)
    # Within the bounds they answer as before (the Lasso check of ADMM is in tests/incremental/test_bls.py).
    assert np.isfinite(sparse_autoencoder(F, target, 1e-3, 50)).all()
    assert frechet_distance_reference(long[:50], long[:40]) == 0.0


def test_the_rotation_helpers_name_their_arguments():
    """the SO(3) helpers passed their input to SciPy, whose messages name no argument,
    and _left_jacobian turned NaN into NaN."""
    from bidmp.primitives.so3 import (
        _left_jacobian,
        angle_between,
        continuous_log,
        orientation_from_log,
    )

    unit = np.array([[0.0, 0.0, 0.0, 1.0]])
    refused(ValueError, r"q must have shape \(n, 4\)", angle_between, np.ones((2, 3)), unit)
    refused(ValueError, r"goal contains a zero quaternion", continuous_log, unit, np.zeros(4))
    refused(ValueError, r"r contains NaN", _left_jacobian, np.full((2, 3), np.nan))
    refused(
        ValueError, r"error must have shape \(n, 3\)", orientation_from_log, np.ones((2, 4)), unit
    )
    refused(TypeError, r"q must be real numbers", angle_between, unit.astype(complex), unit)
    turn = np.array([[0.0, 0.0, np.sin(0.5), np.cos(0.5)]])  # 1 rad about z
    assert angle_between(turn, unit)[0] == pytest.approx(1.0, abs=1e-12)


def test_the_timing_and_pose_helpers_refuse_bad_input_by_name():
    """the timing and pose helpers (each case below failed before: an internal error,
    a silent NaN, a ComplexWarning or a RuntimeWarning): on 17 entry points x 16 nasty inputs,
    every call returns finite numbers or raises ValueError/TypeError with a message of at most
    300 characters, and no warning escapes."""
    from bidmp.primitives import cartesian, timing

    y = np.linspace([0.0, 0.0, 0.0], [1.0, 2.0, 3.0], 20)
    t = np.linspace(0.0, 1.0, 20)
    trajectory = timing.Trajectory(t, y, np.gradient(y, t, axis=0), np.zeros_like(y))
    q = np.tile([0.0, 0.0, 0.0, 1.0], (20, 1))
    nasty = [
        None,
        "abc",
        np.full((20, 3), np.nan),
        np.full((20, 3), np.inf),
        np.zeros((0, 3)),
        np.zeros(20),
        np.zeros((2, 20, 3)),
        y + 1j,
        y * 1e300,
        np.array([object()] * 3),
        -t,
        np.zeros(20),
        5.0,
        ["a", "b"],
        True,
        y * 1e-300,
    ]
    calls = [
        lambda v: timing.check_timestamps(v, 20),
        lambda v: timing.drop_repeated_stamps(v, t),
        lambda v: timing.drop_repeated_stamps(y, v),
        lambda v: timing.uniform_time(v, t),
        lambda v: timing.uniform_time(y, v),
        lambda v: timing.on_uniform_time(v, t),
        lambda v: timing.on_uniform_time(y, v),
        lambda v: timing.scale_factor(v, max_velocity=1.0),
        lambda v: timing.scale_factor(trajectory, max_velocity=v),
        lambda v: timing.time_scale(v, max_velocity=1.0),
        lambda v: timing.time_scale(trajectory, max_velocity=v),
        cartesian.as_quaternions,
        cartesian.as_poses,
        cartesian.continuous_quaternions,
        lambda v: cartesian.orientation_error(v, q),
        lambda v: cartesian.orientation_error(q, v),
        lambda v: cartesian.angle_between(v, q),
    ]
    failures = nasty_failures(calls, nasty)
    assert not failures, failures


def test_the_roadmap_similarity_and_metric_helpers_refuse_bad_input_by_name():
    """the same check on ``template``, ``polyline_length`` and ``rmse`` (18 cases failed before:
    internal errors, silent NaN, leaked warnings). (The roadmap's shortest path is a private core
    that trusts the nodes G-PRM draws: its input is checked where the roadmap's is.) An approach
    error of inf is the documented answer for a motion with no final descent, not a silent one."""
    from bidmp.extension import roadmap, similarity
    from bidmp.tasks import metrics

    y = np.linspace([0.0, 0.0, 0.0], [1.0, 2.0, 3.0], 20)
    nasty = [
        None,
        "abc",
        np.full((20, 3), np.nan),
        np.full((20, 3), np.inf),
        np.zeros((0, 3)),
        np.zeros(20),
        np.zeros((2, 20, 3)),
        y + 1j,
        y * 1e300,
        np.array([object()] * 3),
        5.0,
        ["a", "b"],
        True,
    ]
    calls = [
        lambda v: roadmap.template(v, y[-1] + 5),
        lambda v: roadmap.template(y, v),
        similarity.polyline_length,
        lambda v: metrics.rmse(v, y),
        lambda v: metrics.rmse(y, v),
    ]
    failures = nasty_failures(calls, nasty)
    assert not failures, failures


def nasty_failures(calls, nasty) -> list:
    """Every (call, input) pair that does not either return finite numbers or raise
    ValueError/TypeError with at most 300 characters, with no warning escaping: (call index,
    input index, what happened)."""
    import itertools
    import warnings

    failures = []
    for (index, call), (case, value) in itertools.product(enumerate(calls), enumerate(nasty)):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                result = call(value)
                for part in result if isinstance(result, tuple) else (result,):
                    values = (
                        np.asarray(getattr(part, "y", part), dtype=float)
                        if part is not None
                        else None
                    )
                    if values is not None and values.size and not np.all(np.isfinite(values)):
                        failures.append((index, case, "silent NaN/inf"))
            except (ValueError, TypeError) as exc:
                if len(str(exc)) > 300:
                    failures.append((index, case, "message of", len(str(exc))))
            except Exception as exc:  # an internal error, or a warning turned into one
                failures.append((index, case, type(exc).__name__))
    return failures


def test_the_scene_helpers_refuse_bad_input_by_name():
    """the scene: ``parts_at``, the roadmap checker and its straight moves, and
    oriented clearance (11 cases failed before: IndexError, ComplexWarning, an overflow)."""
    from bidmp.scene import Scene

    scene = Scene.from_dict(
        {
            "tool": {"radius": 10, "length": 100},
            "parts": [{"type": "box", "label": "b", "at": [0, 0, 0], "size": [10, 10, 10]}],
        }
    )
    y = np.linspace([0.0, 0.0, 30.0], [50.0, 0.0, 30.0], 20)
    nasty = [
        None,
        "abc",
        np.full((20, 3), np.nan),
        np.full((20, 3), np.inf),
        np.zeros((0, 3)),
        np.zeros(20),
        np.zeros((2, 20, 3)),
        y + 1j,
        y * 1e300,
        np.array([object()] * 3),
        5.0,
        ["a", "b"],
        True,
    ]
    calls = [
        scene.parts_at,
        scene.checker(),
        lambda v: scene.checker().segments_free(v, y),
        lambda v: scene.clearance(y, orientations=v).distance,
    ]
    failures = nasty_failures(calls, nasty)
    assert not failures, failures


def test_the_writers_and_plots_name_a_wrong_object(tmp_path):
    """They read attributes of what they are given: a wrong object was an AttributeError."""
    import bidmp.experiments
    import bidmp.plotting
    import bidmp.sim
    import bidmp.tasks

    calls = [
        (bidmp.plotting.plot_extension, "extension"),
        (bidmp.plotting.plot_error_vs_distance, "report"),
        (bidmp.plotting.plot_scenario_3d, "report"),
        (bidmp.plotting.plot_targets_top_view, "report"),
        (bidmp.plotting.plot_generalisation, "result"),
        (bidmp.tasks.write_report, "report"),
        (bidmp.experiments.write_results, "result"),
        (bidmp.sim.write_job_report, "report"),
        (bidmp.sim.write_sim_report, "report"),
    ]
    for function, name in calls:
        arguments = {
            bidmp.plotting.plot_extension: (tmp_path / "e.png", object()),
            bidmp.plotting.plot_generalisation: (tmp_path / "g.png", object()),
            bidmp.experiments.write_results: (object(), "x", tmp_path),
        }.get(function, None)
        if arguments is None:
            arguments = (
                (tmp_path / "p.png", object())
                if function.__module__.startswith("bidmp.plotting")
                else (object(), tmp_path)
            )
        with pytest.raises(TypeError, match=rf"^{name} must be .*, got object$"):
            function(*arguments)


def test_a_generalisation_result_is_written_with_its_figure(tmp_path):
    """write_results took every reproduction result but the generalisation's (no markdown())."""
    import json

    from bidmp.experiments import lasa_generalisation, write_results

    result = lasa_generalisation("Sshape")
    written = write_results(result, "generalisation", tmp_path)
    assert [path.name for path in written] == [
        "generalisation.json",
        "generalisation.md",
        "generalisation.png",
    ]
    assert json.loads(written[0].read_text()) == json.loads(json.dumps(result.to_dict()))
    assert result.summary() in written[1].read_text()
