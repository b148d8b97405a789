"""Fuzzing every public entry point and every CLI command: DMP, pose DMP and
Bi-DMP, BLS, extension and roadmaps, baselines, datasets, metrics, plotting, scenarios, scene
geometry, the simulator's IK and planning, the LASA benchmark, every file reader.

Contract checked on every generated input:

* library: the call returns a result without NaN/inf, or raises ``ValueError``/``TypeError``;
* CLI: exit 0, or exit 2 with exactly one line on stderr (no traceback, no "internal error");
* both: no warning of any kind, at most 10 s per call, and the process stays below 2 GB.

In CI every test runs a small number of examples (the whole module takes well under a minute);
``make fuzz`` sets ``BIDMP_FUZZ=full`` for the long campaign (over 10 000 examples in all) and
writes the outcome counts to ``fuzz-report.json``.
"""

import contextlib
import dataclasses
import io
import json
import os
import resource
import shutil
import tempfile
import warnings
import zipfile
from collections import Counter

import numpy as np
import pytest
from conftest import curved_demo

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import bidmp  # noqa: E402
from bidmp.cli import main  # noqa: E402

FULL = os.environ.get("BIDMP_FUZZ") == "full"
SCALE = 20 if FULL else 1
MAX_RSS_BYTES = 2 << 30
OUTCOMES: Counter = Counter()


def examples(n_ci: int) -> settings:
    return settings(
        max_examples=n_ci * SCALE,
        deadline=None,
        derandomize=not FULL,
        database=None,
        suppress_health_check=list(HealthCheck),
    )


def _inf_as_none(value):
    return None if value == float("inf") else value


def _check_finite(value, where="result"):
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc":
            assert np.all(np.isfinite(value)), f"{where} contains NaN/inf"
    elif isinstance(value, float):
        assert np.isfinite(value), f"{where} is {value}"
    elif isinstance(value, (tuple, list)):
        for index, item in enumerate(value):
            _check_finite(item, f"{where}[{index}]")
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for field in dataclasses.fields(value):
            # Documented NaN: an extension's similarity when G-PRM was skipped; forgetting errors of
            # a skill before it was learned (upper triangle of the error matrix).
            if (field.name, type(value).__name__) not in (
                ("similarity", "ExtendedDemonstration"),
                ("errors", "ForgettingResult"),
            ):
                _check_finite(getattr(value, field.name), f"{where}.{field.name}")


def _rss_ok():
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux
    assert peak < MAX_RSS_BYTES, f"peak memory {peak / 2**30:.2f} GiB"


def outcome(name, function, *args, **kwargs):
    """Call a library entry point under the contract; return its result or None."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # The one documented warning: quaternions off unit length are normalised, and said so.
        warnings.filterwarnings(
            "ignore", message=".*not of unit length.*normalised", category=UserWarning
        )
        try:
            result = function(*args, **kwargs)
        except (ValueError, TypeError) as exc:
            assert str(exc), f"{name}: an empty error message"
            OUTCOMES[f"{name}: {type(exc).__name__}"] += 1
            result = None
        else:
            _check_finite(result, name)
            OUTCOMES[f"{name}: result"] += 1
    return result


def run_cli(argv, cwd, label=None):
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(), contextlib.chdir(cwd):
        warnings.simplefilter("error")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main([str(a) for a in argv])
            except SystemExit as exc:  # argparse: usage errors, --help
                code = exc.code
    err = err.getvalue()
    assert "Traceback" not in err and "internal error" not in err, (argv, err)
    assert code in (0, 2, 3), (argv, code, err)  # 3: a run whose targets did not all succeed
    if code == 2:
        assert len(err.strip().splitlines()) == 1, (argv, err)
    else:
        assert "Warning" not in err, (argv, err)
    OUTCOMES[f"cli {label or (argv[0] if argv else '-')}: exit {code}"] += 1
    return code, out.getvalue()


@pytest.fixture(scope="module", autouse=True)
def report():
    # A valid input may allocate arrays up to max_array_bytes (1 GiB by default), several at a
    # time: the campaign runs with a quarter of it, so that one process of many examples stays
    # within MAX_RSS_BYTES while the limits themselves are exercised.
    with bidmp.set_limits(max_array_bytes=256 << 20):
        yield
    _rss_ok()
    if FULL:
        with open("fuzz-report.json", "w", encoding="utf-8") as handle:
            json.dump(
                {"examples": sum(OUTCOMES.values()), "outcomes": dict(sorted(OUTCOMES.items()))},
                handle,
                indent=2,
            )


# ---------------------------------------------------------------------------------------------
# Strategies
# ---------------------------------------------------------------------------------------------
nasty_floats = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from(
        [0.0, -0.0, 1e-300, 5e-324, 1e300, -1e300, 1e12, 1e9, 1e-9, 1.0, -1.0, 0.5, 25.0, 5000.0]
    ),
)
nasty_ints = st.one_of(
    st.integers(-5, 5),
    st.sampled_from([0, 1, 2, 3, 9, 10, 50, 10**6, 10**9, 10**12, 2**63, -(2**63)]),
    st.integers(-(2**70), 2**70),
)


def maybe(valid, nasty=None):
    """Mostly valid values, sometimes nasty ones: both paths get exercised."""
    return st.one_of(valid, valid, valid, nasty if nasty is not None else nasty_floats)


anything = st.one_of(
    nasty_floats,
    nasty_ints,
    st.booleans(),
    st.none(),
    st.text(max_size=5),
    st.lists(st.floats(-10, 10), max_size=4),
)


@st.composite
def trajectories(draw, min_points=0, max_points=400, dims=(1, 2, 3, 4)):
    """Smooth, noisy, degenerate, scaled and poisoned trajectories."""
    kind = draw(
        st.sampled_from(
            ["curve"] * 6 + ["line", "static", "random", "tiny", "huge", "poisoned", "ragged"]
        )
    )
    n_points = draw(st.integers(min_points, max_points))
    n_dims = draw(st.sampled_from(dims))
    seed = draw(st.integers(0, 2**16))
    rng = np.random.default_rng(seed)
    if kind == "ragged":
        return [[1.0] * draw(st.integers(1, 3)) for _ in range(max(n_points, 1))]
    if n_points == 0:
        return np.empty((0, n_dims))
    y = (
        curved_demo(max(n_points, 2), n_dims, seed)[:n_points]
        if n_points >= 2
        else rng.normal(size=(1, n_dims))
    )
    if kind == "line":
        y = np.linspace(0, 1, n_points)[:, None] * rng.normal(size=n_dims)
    elif kind == "static":
        y = np.ones((n_points, n_dims)) * rng.normal()
    elif kind == "random":
        y = rng.normal(size=(n_points, n_dims))
    y = y * draw(st.sampled_from([1.0, 1000.0, 1e-3])) + draw(st.sampled_from([0.0, 1e3, -50.0]))
    if kind == "tiny":
        y = y * draw(st.sampled_from([1e-12, 1e-200, 1e-310]))
    elif kind == "huge":
        y = y * draw(st.sampled_from([1e10, 1e150, 1e300]))
    elif kind == "poisoned":
        y = y.copy()
        y.flat[draw(st.integers(0, y.size - 1))] = draw(
            st.sampled_from([np.nan, np.inf, -np.inf, 1e308])
        )
    return y


points = st.one_of(
    st.lists(nasty_floats, min_size=0, max_size=5),
    st.none(),
    st.just("goal"),
    st.lists(st.floats(-5, 5), min_size=1, max_size=4),
    st.lists(st.floats(-5, 5), min_size=3, max_size=3),
    st.lists(st.floats(-5, 5), min_size=3, max_size=3),
    st.lists(st.floats(-5, 5), min_size=2, max_size=2),
)
dmp_params = st.fixed_dictionaries(
    {},
    optional={
        "n_kernels": maybe(st.integers(1, 200), nasty_ints),
        "alpha": maybe(st.floats(1.0, 200.0)),
        "beta": st.one_of(st.none(), maybe(st.floats(0.5, 50.0))),
        "K": st.one_of(st.sampled_from(["paper", "pastor", "other"]), maybe(st.floats(1.0, 1e3))),
        "alpha_phase": maybe(st.floats(0.1, 5.0)),
        "tau": maybe(st.floats(0.2, 5.0)),
        "regression": st.sampled_from(["lwr", "ridge", "x"]),
        "derivatives": st.sampled_from(["gradient", "forward"]),
        "ridge": maybe(st.floats(0.0, 1e-3)),
        "widths": st.sampled_from(["spacing", "pydmps"]),
    },
)
small_floats = st.floats(-3, 3)


def good_demo(n_points=150, n_dims=3, seed=0):
    return curved_demo(n_points, n_dims, seed)


# ---------------------------------------------------------------------------------------------
# Library entry points
# ---------------------------------------------------------------------------------------------
@given(trajectories(), dmp_params, points, points, st.one_of(st.none(), nasty_ints))
@examples(60)
def test_fuzz_dmp(y, params, goal, start, n_steps):
    dmp = outcome("DMP.fit", bidmp.DMP(**params).fit, y)
    if dmp is None:
        dmp = bidmp.DMP().fit(good_demo(100, 3))
    outcome("DMP.rollout", dmp.rollout, goal=goal, start=start, n_steps=n_steps)
    outcome(
        "DMP.rollout_many",
        dmp.rollout_many,
        [goal, goal] if isinstance(goal, list) else goal,
        n_steps=n_steps,
    )
    outcome("DMP.endpoint_gain", dmp.endpoint_gain, n_steps)


@given(
    trajectories(),
    st.one_of(nasty_floats, st.floats(0.01, 0.9)),
    st.sampled_from(["persistence", "paper", "x"]),
)
@examples(60)
def test_fuzz_segment(y, eps_frac, method):
    outcome("segment", bidmp.segment, y, eps_frac=eps_frac, method=method)
    outcome("curvature", bidmp.extension.curvature, y)


timestamps = st.one_of(
    st.none(),
    st.sampled_from(["uniform", "jitter", "epoch", "ms", "duplicate", "reverse", "nan", "short"]),
)


def _stamps(kind, n):
    base = np.arange(n) / 250.0
    return {
        None: None,
        "uniform": base,
        "jitter": base + np.r_[0, np.full(max(n - 2, 0), 1e-3), 0][:n],
        "epoch": base + 1.7e9,
        "ms": base * 1000.0,
        "duplicate": np.r_[base[:1], base[:-1]],
        "reverse": base[::-1],
        "nan": np.r_[base[:-1], np.nan],
        "short": base[:-1],
    }[kind]


@given(
    trajectories(min_points=3, max_points=300, dims=(2, 3)),
    timestamps,
    dmp_params,
    points,
    points,
    st.one_of(st.none(), maybe(st.floats(0.05, 20.0))),
    st.one_of(st.none(), maybe(st.floats(1e-4, 0.05))),
    st.one_of(
        st.none(),
        st.fixed_dictionaries(
            {},
            optional={
                "max_velocity": maybe(st.floats(0.1, 1e3)),
                "max_acceleration": maybe(st.floats(0.1, 1e4)),
                "norm": st.sampled_from(["norm", "axis", "x"]),
            },
        ),
    ),
)
@examples(50)
def test_fuzz_timed_dmp(  # noqa: PLR0913 - one argument per hypothesis strategy
    y, stamps, params, goal, start, duration, dt, limits
):
    n = len(y) if hasattr(y, "__len__") else 0
    dmp = outcome("DMP.fit(t)", bidmp.DMP(**params).fit, y, _stamps(stamps, n))
    if dmp is None:
        dmp = bidmp.DMP().fit(good_demo(100, 3), np.arange(100) / 100.0)
    trajectory = outcome(
        "DMP.trajectory",
        dmp.trajectory,
        goal=goal,
        start=start,
        duration=duration,
        dt=dt,
        limits=limits,
    )
    if trajectory is not None:
        outcome(
            "time_scale", bidmp.time_scale, trajectory, max_velocity=duration, max_acceleration=dt
        )
    stepper = outcome(
        "DMP.stepper", dmp.stepper, goal=goal, start=start, duration=duration, coupling=1.0
    )
    if stepper is not None:
        for _ in range(3):
            outcome("stepper.step", stepper.step, dt if dt is not None else 0.004, goal)


@given(
    trajectories(min_points=0, max_points=600, dims=(2, 3)),
    timestamps,
    maybe(st.floats(0.5, 20.0)),
    maybe(st.floats(0.01, 0.3)),
    maybe(st.integers(0, 50), nasty_ints),
)
@examples(40)
def test_fuzz_prepare_and_recordings(y, stamps, cutoff, fraction, seed):
    n = len(y) if hasattr(y, "__len__") else 0
    outcome(
        "prepare", bidmp.prepare, y, _stamps(stamps, n), cutoff_hz=cutoff, idle_fraction=fraction
    )
    recording = outcome(
        "kinesthetic_recording",
        bidmp.demonstrations.kinesthetic_recording,
        [[0, 0, 0], [50, 20, 10]],
        seed=seed,
        duration=cutoff,
        idle=fraction,
    )
    if recording is not None:
        outcome("prepare(recording)", bidmp.prepare, *recording)


@given(
    trajectories(max_points=200), trajectories(max_points=200), st.sampled_from(["sqrt2", "2", "3"])
)
@examples(60)
def test_fuzz_frechet(a, b, denom):
    outcome("frechet_distance", bidmp.frechet_distance, a, b)
    outcome("frechet_similarity", bidmp.frechet_similarity, a, b, denom=denom)


extension_options = st.fixed_dictionaries(
    {},
    optional={
        "eps_frac": maybe(st.floats(0.01, 0.5)),
        "n_samples": maybe(st.integers(2, 400), nasty_ints),
        "sigma_rel": maybe(st.floats(0.0, 0.2)),
        "n_neighbours": maybe(st.integers(1, 20), nasty_ints),
        "n_compare": maybe(st.integers(3, 150), nasty_ints),
        "n_iter": maybe(st.integers(1, 12), nasty_ints),
        "rho": maybe(st.floats(0.1, 1.0)),
        "schedule": st.sampled_from(["geometric", "harmonic", "x"]),
        "scaling": st.sampled_from(["axis", "similarity", "paper", "x"]),
        "compare": st.sampled_from(["template", "raw"]),
        "select": st.sampled_from(["best", "last"]),
        "denom": st.sampled_from(["sqrt2", "2"]),
        "method": st.sampled_from(["persistence", "paper"]),
    },
)


@given(
    trajectories(max_points=300, dims=(2, 3)),
    points,
    maybe(st.integers(0, 2**32), st.one_of(nasty_ints, anything)),
    extension_options,
)
@examples(30)
def test_fuzz_extend_demonstration(y, target, seed, options):
    outcome("extend_demonstration", _extend_with_flat_options, y, target, seed, options)


def _extend_with_flat_options(y, target, seed, options):
    """``extend_demonstration`` with options as a scenario file writes them (flat)."""
    from bidmp.extension import check_extension_options

    options = dict(options)
    segmentation = {k: options.pop(k) for k in ("eps_frac", "method") if k in options}
    arguments = check_extension_options(**segmentation, **options)
    return bidmp.extend_demonstration(y, target, seed=seed, **arguments)


@given(
    trajectories(max_points=200, dims=(2, 3)),
    points,
    maybe(st.integers(0, 99), nasty_ints),
    st.sampled_from(["gaussian", "classic"]),
    extension_options,
)
@examples(30)
def test_fuzz_roadmaps(piece, target, seed, which, options):
    from bidmp.extension import RoadmapOptions, classic_prm, gaussian_prm

    options = {k: v for k, v in options.items() if k not in ("eps_frac", "method")}

    def run(piece, target, seed):
        roadmap = classic_prm if which == "classic" else gaussian_prm
        return roadmap(piece, target, RoadmapOptions(**options), seed=seed)

    outcome(f"{which}_prm", run, piece, target, seed)


bls_params = st.fixed_dictionaries(
    {},
    optional={
        "n_windows": maybe(st.integers(1, 12), nasty_ints),
        "n_mapped": maybe(st.integers(1, 12), nasty_ints),
        "n_enhance": maybe(st.integers(1, 150), nasty_ints),
        "shrink": maybe(st.floats(0.1, 2.0)),
        "reg": maybe(st.sampled_from([0.0, 1e-8, 1e-4, 1e-2])),
        "l1": maybe(st.floats(0.0, 0.1)),
        "admm_iterations": maybe(st.integers(1, 60), nasty_ints),
        "update": st.sampled_from(["auto", "pinv", "exact_ridge", "x"]),
        "seed": maybe(st.integers(0, 100), nasty_ints),
    },
)


@given(
    trajectories(max_points=300),
    trajectories(max_points=300),
    bls_params,
    maybe(st.integers(1, 50), nasty_ints),
)
@examples(50)
def test_fuzz_bls(X, Y, params, n_nodes):
    if isinstance(X, np.ndarray) and isinstance(Y, np.ndarray) and X.ndim == 2 and Y.ndim == 2:
        Y = Y[: X.shape[0]] if Y.shape[0] >= X.shape[0] else Y
    model = outcome("BLS.fit", bidmp.BLS(**params).fit, X, Y)
    if model is not None:
        outcome("BLS.add_enhancement_nodes", model.add_enhancement_nodes, n_nodes)
        outcome("BLS.predict", model.predict, X)


bidmp_params = st.fixed_dictionaries(
    {},
    optional={
        "n_windows": st.one_of(nasty_ints, st.integers(1, 12)),
        "n_mapped": st.one_of(nasty_ints, st.integers(1, 12)),
        "n_enhance": st.one_of(nasty_ints, st.integers(1, 120)),
        "shrink": maybe(st.floats(0.1, 2.0)),
        "reg": maybe(st.sampled_from([1e-6, 1e-4, 1e-2])),
        "increments": st.one_of(
            st.lists(st.integers(1, 30), max_size=3).map(tuple),
            st.lists(st.one_of(nasty_ints, st.integers(1, 30)), max_size=3).map(tuple),
            anything,
        ),
        "seed": maybe(st.integers(0, 100), nasty_ints),
        "derivatives": st.sampled_from(["forward", "gradient", "dmp", "x"]),
    },
)


@given(
    trajectories(max_points=300, dims=(3,)),
    bidmp_params,
    points,
    st.one_of(st.sampled_from(["nearest", "latest", "nearest", "x"]), nasty_ints),
)
@examples(40)
def test_fuzz_bidmp(y_dn, params, goal, skill):
    model = bidmp.BiDMP(bidmp.DMP().fit(good_demo(120, 3)), **params)
    outcome("BiDMP.learn", model.learn, y_dn)
    outcome("BiDMP.rollout", model.rollout, goal=goal, skill=skill)


@given(st.lists(trajectories(max_points=200, dims=(3,)), max_size=3))
@examples(15)
def test_fuzz_forgetting(demonstrations):
    outcome(
        "forgetting",
        bidmp.forgetting,
        bidmp.DMP().fit(good_demo(120, 3)),
        demonstrations,
        increments=(5,),
    )


mixture_params = st.fixed_dictionaries(
    {},
    optional={
        "n_components": maybe(st.integers(1, 8), nasty_ints),
        "reg_covar": maybe(st.floats(1e-6, 1e-2)),
        "n_copies": maybe(st.integers(0, 3), nasty_ints),
        "noise": maybe(st.floats(0.0, 2.0)),
        "seed": maybe(st.integers(0, 100), nasty_ints),
    },
)


@given(
    trajectories(max_points=150),
    mixture_params,
    points,
    st.one_of(st.none(), nasty_ints),
    st.booleans(),
)
@examples(15)
def test_fuzz_baselines(y, params, target, n_steps, task_parameterised):
    from bidmp.baselines import TPGMM, GMMRegressor

    if task_parameterised:
        model = outcome("TPGMM.fit", TPGMM(**params).fit, y)
        if model is not None:
            outcome(
                "TPGMM.rollout",
                model.rollout,
                target,
                start=np.zeros(model.n_dims_),
                n_steps=n_steps,
            )
    else:
        model = outcome("GMMRegressor.fit", GMMRegressor(**params).fit, y)
        if model is not None:
            outcome("GMMRegressor.rollout", model.rollout, n_steps=n_steps)


@given(
    maybe(
        st.sampled_from(["Sshape", "WShape", "Angle", "heee"]),
        st.one_of(st.text(max_size=12), anything),
    ),
    maybe(
        st.lists(st.lists(st.floats(-100, 100), min_size=3, max_size=3), min_size=2, max_size=6),
        st.lists(st.lists(nasty_floats, min_size=1, max_size=3), max_size=6),
    ),
    maybe(st.integers(3, 3000), nasty_ints),
    maybe(st.floats(0.0, 3.0)),
    maybe(st.integers(0, 2**32), anything),
)
@examples(40)
def test_fuzz_datasets(name, via, n_steps, noise, seed):
    outcome("lasa", bidmp.demonstrations.lasa, name)
    outcome("minimum_jerk", bidmp.demonstrations.minimum_jerk, via, n_steps, noise, seed)


@given(
    trajectories(max_points=100), trajectories(max_points=100), points, maybe(st.floats(0.1, 50.0))
)
@examples(40)
def test_fuzz_metrics(a, b, target, height):
    from bidmp.tasks import metrics

    outcome("metrics.endpoint_error", metrics.endpoint_error, a, target)
    # inf is documented: the motion has no final approach into the target; any other
    # result must be finite.
    outcome(
        "metrics.approach_error",
        lambda *args: _inf_as_none(metrics.approach_error(*args)),
        a,
        target,
        height,
    )
    outcome("metrics.path_difference", metrics.path_difference, a, b)
    outcome("metrics.rmse", metrics.rmse, a, b)
    outcome("metrics.path_extent", metrics.path_extent, a)


@given(
    maybe(st.sampled_from(["Sshape", "Angle"]), st.text(max_size=6)),
    maybe(st.integers(0, 6), nasty_ints),
    maybe(st.integers(1, 4), nasty_ints),
    maybe(st.floats(0.0, 1.0)),
    maybe(st.integers(1, 3), nasty_ints),
)
@examples(10)
def test_fuzz_reproduce_entry_points(name, demo_index, n_goals, shift, factor):
    from bidmp import experiments as reproduce

    outcome(
        "reproduce.lasa_generalisation",
        reproduce.lasa_generalisation,
        name,
        demo_index=demo_index,
        n_goals=n_goals,
        shift=shift,
        convergence_factor=factor,
    )
    outcome(
        "reproduce.compare_prm",
        reproduce.compare_prm,
        good_demo(100, 2),
        [1.5, 1.5],
        n_seeds=n_goals,
    )


@given(
    trajectories(max_points=120, dims=(2, 3)),
    st.lists(trajectories(max_points=120, dims=(2, 3)), max_size=2),
    points,
)
@examples(8)
def test_fuzz_plot_trajectories(demo, rollouts, goal):
    from bidmp.plotting import plot_trajectories

    with tempfile.TemporaryDirectory() as folder:
        outcome(
            "plot_trajectories",
            plot_trajectories,
            os.path.join(folder, "p.png"),
            demo,
            rollouts,
            [f"r{i}" for i in range(len(rollouts))],
            goals=None if goal is None or goal == "goal" else [goal],
        )


# ---------------------------------------------------------------------------------------------
# Files: trajectories, models, scenarios
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fuzz")
    demo = bidmp.io.save_trajectory(good_demo(150, 3), folder / "demo.csv")
    model = bidmp.save(bidmp.DMP().fit(good_demo(150, 3)), folder / "model.npz")
    two_d = bidmp.io.save_trajectory(good_demo(150, 2, seed=3), folder / "demo2.npy")
    bi = bidmp.BiDMP(bidmp.DMP().fit(good_demo(150, 3)), increments=(5,))
    bi.learn(good_demo(150, 3) + 0.2)
    bimodel = bidmp.save(bi, folder / "bidmp.npz")
    (folder / "dir").mkdir()
    (folder / "out").mkdir()
    recording = bidmp.io.save_trajectory(
        bidmp.demonstrations.kinesthetic_recording([[0, 0, 50], [40, 30, 0]], seed=5)[0],
        folder / "recording.csv",
        times=bidmp.demonstrations.kinesthetic_recording([[0, 0, 50], [40, 30, 0]], seed=5)[1],
    )
    return {
        "folder": folder,
        "demo": demo,
        "model": model,
        "demo2": two_d,
        "bidmp": bimodel,
        "recording": recording,
    }


def mutate_bytes(data: bytes, draw_ops) -> bytes:
    data = bytearray(data)
    for kind, position, value in draw_ops:
        if not data:
            break
        position %= len(data)
        if kind == "flip":
            data[position] ^= value & 0xFF
        elif kind == "cut":
            del data[position:]
        elif kind == "insert":
            data[position:position] = bytes([value & 0xFF]) * (value % 7 + 1)
        else:
            data[position : position + 8] = b"\x00" * 8
    return bytes(data)


byte_ops = st.lists(
    st.tuples(
        st.sampled_from(["flip", "cut", "insert", "zero"]),
        st.integers(0, 2**20),
        st.integers(0, 2**16),
    ),
    max_size=4,
)


@given(
    st.sampled_from(["demo", "demo2", "model"]),
    byte_ops,
    st.sampled_from([".csv", ".npy", ".txt", ".npz"]),
)
@examples(80)
def test_fuzz_trajectory_files(files, source, ops, suffix):
    data = mutate_bytes(files[source].read_bytes(), ops)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "f" + suffix)
        with open(path, "wb") as handle:
            handle.write(data)
        outcome("load_trajectory", bidmp.io.load_trajectory, path)


csv_cell = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(max_size=6),
    st.just(""),
    st.sampled_from(
        ["1e999", "0x10", "1_000", "\ufeff1", "nan", "-inf", "1e300", " 3 ", "#", "t", "x"]
    ),
)


@given(
    st.data(),
    st.sampled_from(["", "x,y\n", "t,x,y,z\n", "x,y,z\n", "\ufefft,x,y\n", "time,x,y\n", "a,b\n"]),
    st.sampled_from([",", ",", ";", "\t"]),
)
@examples(80)
def test_fuzz_csv_text(files, data, header, delimiter):
    n_columns = data.draw(st.integers(1, 5))
    n_rows = data.draw(st.integers(0, 40))
    values = curved_demo(max(n_rows, 2), n_columns, data.draw(st.integers(0, 99)))[:n_rows]
    if header.startswith(("t,", "\ufefft", "time")):
        values[:, 0] = (
            np.sort(np.abs(values[:, 0])) * 10
            + np.arange(n_rows) * 0.004
            + 1.7e9 * data.draw(st.booleans())
        )
    rows = [[repr(float(v)) for v in row] for row in values]
    for _ in range(data.draw(st.integers(0, 3))):  # a few broken cells or rows
        if rows:
            row = rows[data.draw(st.integers(0, len(rows) - 1))]
            if data.draw(st.booleans()):
                row[data.draw(st.integers(0, len(row) - 1))] = data.draw(csv_cell)
            else:
                row.append(data.draw(csv_cell))
    text = header + "\n".join(delimiter.join(row) for row in rows) + "\n"
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "f.csv")
        with open(path, "w", encoding="utf-8", errors="surrogatepass") as handle:
            handle.write(text)
        outcome("load_trajectory(csv)", bidmp.io.load_trajectory, path)


@given(st.sampled_from(["model", "bidmp"]), byte_ops, st.data())
@examples(80)
def test_fuzz_model_files(files, source, ops, data):
    original = files[source].read_bytes()
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "m.npz")
        mode = data.draw(st.sampled_from(["bytes", "member", "meta"]))
        if mode == "bytes":
            payload = mutate_bytes(original, ops)
            with open(path, "wb") as handle:
                handle.write(payload)
        else:
            with zipfile.ZipFile(io.BytesIO(original)) as archive:
                members = {info.filename: archive.read(info) for info in archive.infolist()}
            if mode == "member":
                name = data.draw(st.sampled_from(sorted(members)))
                replacement = data.draw(st.sampled_from(["nan", "shape", "dtype", "raw", "bytes"]))
                array = (
                    np.load(io.BytesIO(members[name])) if name != "__bidmp__.npy" else np.zeros(3)
                )
                if replacement == "nan":
                    array = np.array(array, dtype=float)
                    array.flat[0] = np.nan
                elif replacement == "shape":
                    array = np.ones(data.draw(st.sampled_from([(1,), (2, 2), (0,), (3, 1, 1)])))
                elif replacement == "dtype":
                    array = np.array(["a"] * max(array.size, 1))
                buffer = io.BytesIO()
                np.save(buffer, array, allow_pickle=False)
                members[name] = (
                    b"raw" * 10
                    if replacement == "raw"
                    else mutate_bytes(buffer.getvalue(), ops)
                    if replacement == "bytes"
                    else buffer.getvalue()
                )
            else:
                meta = json.loads(np.load(io.BytesIO(members["__bidmp__.npy"])).tobytes())
                path_keys = data.draw(
                    st.lists(
                        st.sampled_from(
                            [
                                "state",
                                "params",
                                "dmp",
                                "blocks",
                                "n_steps_",
                                "format_version",
                                "class",
                                "alpha",
                                "n_kernels",
                                "increments",
                                "phase_min_",
                                "n_blocks",
                                "n_features_",
                                "y_was_1d",
                            ]
                        ),
                        min_size=1,
                        max_size=3,
                    )
                )
                target = meta
                for key in path_keys[:-1]:
                    target = target.get(key, {}) if isinstance(target, dict) else {}
                if isinstance(target, dict):
                    target[path_keys[-1]] = data.draw(anything)
                text = json.dumps(meta, allow_nan=True)
                members["__bidmp__.npy"] = _npy(np.frombuffer(text.encode(), np.uint8))
            with zipfile.ZipFile(path, "w") as archive:
                for name, payload in members.items():
                    archive.writestr(name, payload)
        model = outcome("load", bidmp.load, path)
        if model is not None:
            outcome("loaded.rollout", model.rollout)


def _npy(array):
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    return buffer.getvalue()


scenario_values = st.one_of(
    anything,
    st.dictionaries(st.text(max_size=4), anything, max_size=3),
    st.lists(st.lists(nasty_floats, min_size=3, max_size=3), max_size=4),
)
scenario_keys = st.sampled_from(
    [
        "name",
        "targets",
        "demonstrated",
        "demonstration",
        "success_threshold",
        "approach_height",
        "dmp",
        "bidmp",
        "extension",
        "extension_target",
        "extensions",
        "demonstrations",
        "methods",
        "seed",
        "units",
        "colour",
        "scene",
    ]
)
inner_keys = {
    "dmp": ["alpha", "tau", "n_kernels", "alpha_phase", "K", "beta", "regression"],
    "bidmp": ["n_enhance", "increments", "reg", "seed", "n_windows"],
    "extension": ["n_samples", "n_iter", "rho", "sigma_rel", "n_compare", "scaling"],
    "targets": ["nut1", "nut2", "zz"],
}


@given(
    st.lists(
        st.tuples(
            scenario_keys,
            st.one_of(
                st.none(), st.sampled_from(sorted({k for v in inner_keys.values() for k in v}))
            ),
            scenario_values,
        ),
        min_size=1,
        max_size=3,
    )
)
@examples(60)
def test_fuzz_scenarios(files, changes):
    from bidmp.tasks import scenarios

    data = json.loads(scenarios.builtin_text("nut-unscrewing"))
    for key, inner, value in changes:
        if inner is not None and key in inner_keys and isinstance(data.get(key, {}), dict):
            data.setdefault(key, {})[inner] = value
        else:
            data[key] = value
    scenario = outcome(
        "scenarios.from_dict", scenarios.from_dict, data, "fuzz", str(files["folder"])
    )
    if scenario is not None:
        outcome("evaluate(dmp)", bidmp.evaluate, scenario, ["dmp"])


scene_part_keys = st.sampled_from(
    [
        "type",
        "label",
        "at",
        "at_targets",
        "offset",
        "size",
        "radius",
        "height",
        "across_flats",
        "stud",
        "yaw",
        "colour",
    ]
)


@given(
    st.lists(
        st.tuples(
            st.sampled_from(
                ["tool", "parts", "targets", "targets_on_parts", "colour", "part", "plate"]
            ),
            scene_part_keys,
            st.one_of(scenario_values, st.sampled_from(["all", "nut", "box", "3", [], {}])),
        ),
        min_size=1,
        max_size=3,
    ),
    trajectories(max_points=60, dims=(3,)),
)
@examples(60)
def test_fuzz_scene(changes, trajectory):
    from bidmp.scene import Scene
    from bidmp.tasks import scenarios

    data = json.loads(scenarios.builtin_text("nut-unscrewing"))
    scene, targets = data["scene"], data["targets"]
    for key, inner, value in changes:
        parts = scene.get("parts")
        if (
            key in ("part", "plate")
            and isinstance(parts, list)
            and len(parts) == 2
            and isinstance(parts[-1], dict)
        ):
            parts[0 if key == "plate" else 1][inner] = value
        elif key == "tool" and isinstance(scene.get("tool"), dict):
            scene["tool"]["radius" if inner < "m" else "length"] = value
        else:
            scene[key] = value
    result = outcome("Scene.from_dict", Scene.from_dict, scene, targets)
    if result is not None:
        outcome(
            "Scene.clearance",
            result.clearance,
            trajectory,
            exclude=[p for p in ("3",) if p in result.labels],
        )
        outcome("Scene.checker", result.checker(), trajectory)


@st.composite
def pose_arrays(draw, max_points=200):
    """Pose demonstrations (T, 7): positions from :func:`trajectories` with quaternions that
    turn (several times, or not at all), flip sign, leave unit length, vanish or are poisoned."""
    from scipy.spatial.transform import Rotation

    positions = draw(trajectories(max_points=max_points, dims=(3,)))
    if (
        not isinstance(positions, np.ndarray)
        or positions.ndim != 2
        or positions.shape[1] != 3
        or len(positions) == 0
    ):
        return positions
    n = len(positions)
    turn = draw(st.sampled_from([0.0, 0.5, 3.0, 7.0, 13.0]))  # rad: none, small, past pi, two turns
    axis = np.random.default_rng(draw(st.integers(0, 99))).normal(size=3)
    quaternions = Rotation.from_rotvec(
        np.outer(np.linspace(0, turn, n), axis / np.linalg.norm(axis))
    ).as_quat()
    kind = draw(st.sampled_from(["plain"] * 4 + ["flips", "scaled", "zero", "poisoned", "huge"]))
    if kind == "flips":
        quaternions[::3] *= -1.0
    elif kind == "scaled":
        quaternions *= draw(st.sampled_from([1.001, 3.0, 1e-200, 1e200]))
    elif kind == "zero":
        quaternions[draw(st.integers(0, n - 1))] = 0.0
    elif kind == "poisoned":
        quaternions.flat[draw(st.integers(0, quaternions.size - 1))] = draw(
            st.sampled_from([np.nan, np.inf])
        )
    elif kind == "huge":
        quaternions = quaternions * 1e308
    return np.hstack([positions, quaternions])


pose_points = st.one_of(
    points,
    st.lists(st.floats(-5, 5), min_size=7, max_size=7),
    st.just([1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0]),
    st.just([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
)


def good_poses(n_points=120):
    from scipy.spatial.transform import Rotation

    quaternions = Rotation.from_rotvec(
        np.outer(np.linspace(0, 4.0, n_points), [0.0, 0.0, 1.0])
    ).as_quat()
    return np.hstack([good_demo(n_points, 3), quaternions])


@given(
    pose_arrays(),
    dmp_params,
    pose_points,
    pose_points,
    st.one_of(st.none(), st.floats(0.2, 5.0), nasty_floats),
)
@examples(40)
def test_fuzz_cartesian(poses, params, goal, start, duration):
    model = outcome("CartesianDMP.fit", bidmp.CartesianDMP(bidmp.DMP(**params)).fit, poses)
    if model is None:
        model = bidmp.CartesianDMP().fit(good_poses())
    outcome("CartesianDMP.rollout", model.rollout, goal, start=start)
    motion = outcome(
        "CartesianDMP.trajectory", model.trajectory, goal, start=start, duration=duration
    )
    if motion is not None:
        assert np.all(np.abs(np.linalg.norm(motion.q, axis=1) - 1.0) < 1e-9)
    stepper = outcome("CartesianDMP.stepper", model.stepper, goal, start=start)
    if stepper is not None:
        outcome("PoseStepper.step", stepper.step, 0.01)


@given(
    pose_arrays(),
    maybe(
        st.fixed_dictionaries(
            {},
            optional={
                "increments": st.sampled_from([(5,), (), (3, 3)]),
                "reg": st.floats(1e-6, 1.0),
            },
        )
    ),
    pose_points,
    st.sampled_from(["nearest", "latest", 0, 1, 2, -1, "x"]),
)
@examples(30)
def test_fuzz_cartesian_bidmp(poses, params, goal, skill):
    params = params if isinstance(params, dict) else {"reg": params}
    model = outcome(
        "CartesianBiDMP",
        lambda cartesian, **params: bidmp.CartesianBiDMP(cartesian, bidmp.BiDMP(**params)),
        bidmp.CartesianDMP().fit(good_poses()),
        **params,
    )
    if model is None:
        return
    outcome("CartesianBiDMP.learn", model.learn, poses)
    outcome("CartesianBiDMP.rollout", model.rollout, goal, skill=skill)
    outcome("CartesianBiDMP.trajectory", model.trajectory, goal, skill=skill)


@given(
    st.sampled_from(
        [
            "t,x,y,z,qx,qy,qz,qw",
            "x,y,z,qw,qx,qy,qz",
            "timestamp,x,y,z,qx,qy,qz,qw,grip",
            "t,x,y,z,qx,qy,qz",
            "t,x,y,z,qx,qy,qz,qw,qw",
            "qx,qy,qz,qw",
            "",
        ]
    ),
    pose_arrays(max_points=60),
    st.sampled_from([None, "t=t,x=x,y=y,z=z,qx=qx,qy=qy,qz=qz,qw=qw", "w=x", "t=nope"]),
)
@examples(40)
def test_fuzz_pose_files(files, header, poses, columns):
    path = files["folder"] / "poses.csv"
    rows = np.asarray(poses, dtype=float) if isinstance(poses, np.ndarray) else np.zeros((0, 7))
    width = len(header.split(",")) if header else 7
    table = np.column_stack([np.arange(len(rows)) * 0.01, rows])[:, :width] if len(rows) else rows
    text = (header + "\n" if header else "") + "\n".join(
        ",".join(repr(float(v)) for v in row) for row in table
    )
    path.write_text(text)
    outcome("io.read_poses", bidmp.io.read_poses, path, columns=columns)


@pytest.fixture(scope="module")
def panda():
    pytest.importorskip("pybullet")
    from bidmp.sim import RobotCell, robot_placement
    from bidmp.tasks import scenarios

    scenario = scenarios.load("nut-unscrewing")
    cell = RobotCell(scenario.scene, scenario.units, *robot_placement(scenario))
    yield cell
    cell.close()


@given(
    st.one_of(points, st.just([0.05, -0.1, 0.3])),
    st.one_of(points, st.just([0.0] * 7)),
    st.one_of(
        trajectories(max_points=20, dims=(3,)),
        st.just(np.array([[0.0, 0.0, 40.0], [10.0, 0.0, 20.0]])),
    ),
)
@examples(15)
def test_fuzz_sim(panda, target, seed, path):
    outcome("RobotCell.solve_ik", panda.solve_ik, target, seed)
    outcome("RobotCell.plan", panda.plan, path, seed=seed)


@given(
    maybe(st.lists(st.sampled_from(["Sshape", "Angle", "Nope", ""]), max_size=2), anything),
    maybe(st.lists(st.sampled_from(["dmp-paper", "gmm", "magic"]), max_size=2), anything),
    maybe(st.sampled_from(["first3", "all"]), anything),
    maybe(st.sampled_from([200, 500]), nasty_ints),
)
@examples(12)
def test_fuzz_benchmark(files, shapes, methods, demos, every):
    from bidmp.experiments import benchmark

    if (
        every in (200, 500)
        and demos in ("first3", "all")
        and isinstance(shapes, list)
        and isinstance(methods, list)
    ):
        # a valid sweep stays small: 1-2 shapes x 3 demonstrations of a few samples
        demos = "first3"
    out = files["folder"] / "bench"
    outcome(
        "benchmark.lasa",
        benchmark.lasa,
        out,
        shapes=shapes,
        methods=methods,
        demos=demos,
        every=every,
        synchronous=True,
        output_format="csv",
    )
    shutil.rmtree(out, ignore_errors=True)


# ---------------------------------------------------------------------------------------------
# The command line
# ---------------------------------------------------------------------------------------------
def cli_tokens(files):
    folder = files["folder"]
    paths = [
        files["demo"],
        files["demo2"],
        files["model"],
        files["bidmp"],
        folder / "dir",
        folder / "missing.csv",
        "/dev/null",
        folder / "out.csv",
        folder / "out.npy",
        folder / "out.npz",
        folder / "out",
        folder / "dir" / "x.png",
        "nut-unscrewing",
        "cell-removal",
        "Sshape",
        "nope",
    ]
    numbers = [
        "0",
        "1",
        "-1",
        "2",
        "3",
        "10",
        "25",
        "1e300",
        "-1e300",
        "nan",
        "inf",
        "1e-300",
        str(2**63),
        "1e12",
        "5000",
        "0.001",
        "abc",
        "",
        ",",
    ]
    flags = [
        "-o",
        "--goal",
        "--start",
        "--n-steps",
        "--skill",
        "--plot",
        "--n-kernels",
        "--alpha",
        "--beta",
        "--K",
        "--rate",
        "--duration",
        "--max-speed",
        "--max-acc",
        "--units",
        "--raw",
        "--cutoff",
        "--protocol",
        "--alpha-phase",
        "--tau",
        "--regression",
        "--eps-frac",
        "--method",
        "--target",
        "--save-demo",
        "--seed",
        "--methods",
        "--out",
        "--scenario",
        "--demo",
        "--seeds",
        "--allow-outside-files",
        "--debug-not",
        "--help",
    ]
    return [str(p) for p in paths], numbers, flags


def cli_templates(files):
    """A valid command line per command (the mutations below break them in every way)."""
    folder = files["folder"]
    scenario = folder / "scenario.json"
    if not scenario.exists():
        data = json.loads(bidmp.tasks.builtin_text("pick-and-place"))
        data["methods"] = ["dmp", "bidmp"]
        scenario.write_text(json.dumps(data))
    out = folder / "out"
    return {
        "fit": ["fit", files["demo"], "-o", out / "m.npz", "--alpha", "25", "--n-kernels", "30"],
        "rollout": [
            "rollout",
            files["model"],
            "-o",
            out / "r.csv",
            "--goal",
            "0.5",
            "0.2",
            "0.1",
            "--n-steps",
            "300",
        ],
        "rollout-bidmp": [
            "rollout",
            files["bidmp"],
            "-o",
            out / "r.npy",
            "--skill",
            "nearest",
            "--goal",
            "0.1",
            "0",
            "0",
        ],
        "rollout-timed": [
            "rollout",
            files["model"],
            "-o",
            out / "r.csv",
            "--rate",
            "1000",
            "--max-speed",
            "5",
            "--max-acc",
            "50",
            "--duration",
            "2",
        ],
        "fit-recording": [
            "fit",
            files["recording"],
            "-o",
            out / "m.npz",
            "--units",
            "mm",
            "--cutoff",
            "6",
        ],
        "learn": ["learn", files["model"], files["demo"], "-o", out / "l.npz"],
        "segment": ["segment", files["demo"], "--eps-frac", "0.1", "--method", "persistence"],
        "extend": [
            "extend",
            files["model"],
            files["demo"],
            "--target",
            "1.2",
            "0.9",
            "-0.4",
            "-o",
            out / "e.npz",
        ],
        "lasa-list": ["lasa", "list"],
        "lasa-export": ["lasa", "export", "Sshape", "--demo", "2", "-o", out / "s.csv"],
        "scenario-list": ["scenario", "list"],
        "scenario-show": ["scenario", "show", "cell-removal"],
        "scenario-check": ["scenario", "check", scenario],
        "demo": ["demo", "--scenario", scenario, "--methods", "dmp", "--out", out / "demo"],
        "reproduce": [
            "reproduce",
            "table6",
            "--seeds",
            "3",
            "--out",
            out / "rep",
        ],  # invalid: a valid run is too long
        "none": [],
    }


@given(st.data())
@examples(150)
def test_fuzz_cli(files, data):
    paths, numbers, flags = cli_tokens(files)
    templates = cli_templates(files)
    name = data.draw(st.sampled_from(sorted(templates)))
    argv = [str(token) for token in templates[name]]
    token = st.one_of(
        st.sampled_from(paths),
        st.sampled_from(numbers),
        st.sampled_from(flags),
        st.text(max_size=8).filter(lambda t: "\x00" not in t),
    )
    for _ in range(data.draw(st.integers(0, 3))):
        action = data.draw(st.sampled_from(["replace", "replace", "delete", "insert"]))
        if action == "insert" or not argv:
            argv.insert(data.draw(st.integers(0, len(argv))), data.draw(token))
        elif action == "replace":
            argv[data.draw(st.integers(0, len(argv) - 1))] = data.draw(token)
        elif len(argv) > 1:
            del argv[data.draw(st.integers(1, len(argv) - 1))]
    argv = [a for a in argv if a not in ("--help", "-h")]
    if "reproduce" in argv[:1] and "--seeds" not in argv:
        return  # a real reproduce run takes longer than a fuzz call may (tests/cli/test_cli.py runs them)
    if argv[:1] == ["reproduce"] and any(a in argv for a in ("table4", "table5", "figures")):
        seeds = argv[argv.index("--seeds") + 1] if argv.index("--seeds") + 1 < len(argv) else ""
        if seeds.isdigit() and 1 <= int(seeds) <= 200:
            return
    code, out = run_cli(argv, files["folder"] / "dir", label=name)
    if code == 0:  # every model a successful command wrote loads and rolls out finitely
        import glob
        import re

        for written in re.findall(r"^wrote (\S+\.npz)(?=\s|$)", out, re.MULTILINE):
            # Relative to the command's folder; the CLI prints a control character as '?', which
            # glob reads as "any one character".
            matches = glob.glob(os.path.join(glob.escape(str(files["folder"] / "dir")), written))
            assert matches, (argv, written)
            assert np.all(np.isfinite(bidmp.load(matches[0]).rollout()))
    shutil.rmtree(files["folder"] / "out", ignore_errors=True)
    (files["folder"] / "out").mkdir()
