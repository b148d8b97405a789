"""The DMP as one system: :class:`DMPSettings` (resolved, checked, immutable) and
:class:`DMPSystem` (settings, components, weights and grid, with the rollouts as methods).

What shows correctness here: a system made by hand from random weights, rolled out against a plain
explicit-Euler loop of Eq. 10-14; a system's ``with_tau`` against a DMP fitted with that ``tau``.
What guards structure: the DMP's rollouts are its system's (the same code), the settings are
resolved once per change and again after any change, and no module reaches into another class's
private members.
"""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import pathlib

import numpy as np
import pytest
from conftest import curved_demo

import bidmp
from bidmp import DMP, NotFittedError
from bidmp.primitives import (
    DMPSettings,
    DMPSystem,
    ExponentialPhase,
    GaussianBasis,
    kernel_centres,
    kernel_widths,
)

SRC = pathlib.Path(bidmp.__file__).parent


def paper_settings(n_kernels=12, **changes) -> DMPSettings:
    fields = dict(
        n_kernels=n_kernels,
        alpha=25.0,
        beta=6.25,
        K=25.0,
        alpha_phase=1.0,
        tau=1.0,
        regression="lwr",
        derivatives="gradient",
        ridge=1e-8,
        widths="spacing",
        protocol="paper",
        goal_rate=1.0,
        integrator="euler",
        settle=1.0,
        canonical_system=ExponentialPhase(1.0, exact=False),
        basis=GaussianBasis(n_kernels),
    )
    fields.update(changes)
    return DMPSettings(**fields)


def plain_euler(settings, weights, kernels, ends, n_steps, dt):
    """Eq. 10-14 as a loop: the phase gate, explicit Euler, tau-scaled (written from the formula,
    not from bidmp's integrator); ``kernels`` = (centres, widths), ``ends`` = (start, goal)."""
    (centres, widths), (start, goal) = kernels, ends
    y, z, phase, out = start.copy(), np.zeros_like(start), 1.0, []
    h = dt / settings.tau
    for _ in range(n_steps):
        out.append(y.copy())
        psi = np.exp(-widths * (phase - centres) ** 2)
        forcing = phase * (psi @ weights) / psi.sum()
        acceleration = (
            settings.alpha * (settings.beta * (goal - y) - z)
            + settings.K * forcing
            - settings.K * phase * (goal - start)
        )
        y, z = y + h * z, z + h * acceleration
        phase *= 1.0 - settings.alpha_phase * h
    return np.array(out)


@pytest.mark.parametrize("seed", range(4))
def test_a_system_made_by_hand_rolls_out_as_the_plain_euler_loop(seed):
    """Independent reference: random weights, goal and start, any tau and dimension."""
    rng = np.random.default_rng(seed)
    n_kernels, n_dims, n_samples = int(rng.integers(5, 30)), int(rng.integers(1, 5)), 150
    settings = paper_settings(n_kernels, tau=float(rng.uniform(0.6, 2.0)))
    centres = kernel_centres(n_kernels, n_samples, 1.0 / n_samples)
    widths = kernel_widths(centres)
    weights = rng.normal(scale=50.0, size=(n_kernels, n_dims))
    start, goal = rng.normal(size=(2, n_dims))
    system = DMPSystem(settings, weights, start, goal, n_samples, 2.0, centres, widths)
    n_steps = int(rng.integers(2, 300))
    fast = system.rollout(n_steps=n_steps)
    kernels = (centres, widths)
    slow = plain_euler(settings, weights, kernels, (start, goal), n_steps, 1.0 / n_samples)
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9 * (1 + np.abs(slow).max()))
    # many goals: each the affine rollout to it
    goals = rng.normal(size=(5, n_dims))
    many = system.rollout_many(goals, n_steps=n_steps)
    for index, other in enumerate(goals):
        reference = plain_euler(
            settings, weights, kernels, (start, other), n_steps, 1.0 / n_samples
        )
        np.testing.assert_allclose(
            many[index], reference, atol=1e-9 * (1 + np.abs(reference).max())
        )


@pytest.mark.parametrize("protocol", ["robot", "paper"])
def test_with_tau_is_the_dmp_fitted_with_that_tau(protocol):
    """Independent of the system's own path: a second estimator fitted with tau given."""
    demo = curved_demo(200, 3, seed=5)
    t = np.linspace(0.0, 2.5, 200)
    plain = DMP(protocol=protocol).fit(demo, t)
    slower = DMP(protocol=protocol, tau=1.7).fit(demo, t)
    np.testing.assert_allclose(
        plain.system_.with_tau(1.7).rollout(), slower.rollout(), rtol=0, atol=1e-12
    )
    assert plain.system_.settings.tau == 1.0  # the plain system is untouched


@pytest.mark.parametrize("protocol", ["robot", "paper"])
def test_the_step_integrator_driven_by_the_systems_input_gives_its_rollout(protocol):
    """Two integrations of one system: the compiled LTI path of rollout() against the step
    integrator (a plain loop here) driven by u = αβ g + K f - K gate (g - y0) on the same grid."""
    rng = np.random.default_rng(11)
    demo = curved_demo(160, 2, seed=9)
    system = DMP(protocol=protocol).fit(demo, np.linspace(0.0, 1.6, 160)).system_.with_tau(1.3)
    settings, goal = system.settings, demo[-1] + rng.normal(size=2)
    phase, basis, _, gate = system.grid()
    inputs = (
        settings.alpha * settings.beta * goal
        + settings.K * (basis @ system.weights)
        - settings.K * gate[:, None] * (goal - system.start)
    )
    integrator = system.step_integrator()
    assert system.canonical_system is settings.canonical_system and system.basis is settings.basis
    y, z, stepped = system.start.copy(), np.zeros(2), [system.start.copy()]
    for now, after in zip(inputs[:-1], inputs[1:]):
        y, z = integrator.step(y, z, now, after, system.dt)
        stepped.append(y)
    rollout = system.rollout(goal)
    np.testing.assert_allclose(
        np.array(stepped), rollout, rtol=0, atol=1e-9 * np.abs(rollout).max()
    )


def test_a_dmps_rollouts_are_its_systems():
    """Structure guard: the estimator delegates to its system (the same numbers by construction)."""
    demo = curved_demo(180, 2, seed=2)
    dmp = DMP().fit(demo, np.linspace(0.0, 1.8, 180))
    system = dmp.system_
    goal = demo[-1] + 0.3
    np.testing.assert_array_equal(dmp.rollout(goal), system.rollout(goal))
    np.testing.assert_array_equal(dmp.phase(), system.phase())
    assert dmp.endpoint_gain() == system.endpoint_gain()
    assert system.n_train == dmp.n_train_ and system.time_unit == dmp.time_unit_
    # a system made directly from the fitted state rolls out the same
    direct = DMPSystem(
        dmp.settings(),
        dmp.weights_,
        dmp.start_,
        dmp.goal_,
        dmp.n_steps_,
        dmp.duration_,
        dmp.centres_,
        dmp.widths_,
        dmp.goal_gate_,
    )
    np.testing.assert_allclose(direct.rollout(goal), dmp.rollout(goal), rtol=0, atol=1e-12)


def test_the_models_built_on_a_dmp_hold_its_system():
    """Structure guard: MultiDMP's mean motion and BiDMP's skill 0 are their DMP's system."""
    demo = curved_demo(150, 2, seed=7)
    multi = bidmp.primitives.MultiDMP().fit([demo, demo + 0.05, demo - 0.05])
    np.testing.assert_array_equal(multi.system_.rollout(), multi.rollout())
    skills = bidmp.BiDMP().fit(demo)
    np.testing.assert_array_equal(skills.system_.rollout(), skills.rollout(skill=0))


def test_a_bidmp_query_gives_what_a_control_loop_needs_to_run_the_skill():
    """A learned skill run by hand — the query's DMP stepped with its increment — commands the
    samples of the Bi-DMP's own timed trajectory to that goal."""
    demo = curved_demo(150, 2, seed=8)
    t = np.linspace(0.0, 1.5, 150)
    skills = bidmp.BiDMP(bidmp.DMP().fit(demo, t))
    ramp = np.linspace(0.0, 1.0, 150)[:, None] * np.array([0.8, -0.5])
    skills.learn(demo + ramp)
    goal = demo[-1] + np.array([0.9, -0.4])
    index, goal_q, start, increment, dmp = skills.query(goal)
    assert index == 1 and increment is not None
    motion = skills.trajectory(goal, dt=0.005)
    stepper = dmp.stepper(goal_q, start=start, forcing_increment=increment)
    commands = np.array([stepper.step(0.005)[0] for _ in range(len(motion.t))])
    np.testing.assert_allclose(commands, motion.y, rtol=0, atol=1e-9 * np.abs(motion.y).max())


def test_a_system_and_its_settings_survive_pickle_and_copy():
    """Dask ships models between processes; a copy rolls out what the original does."""
    import copy
    import pickle

    demo = curved_demo(150, 3, seed=6)
    system = DMP().fit(demo, np.linspace(0.0, 1.5, 150)).system_
    for other in (pickle.loads(pickle.dumps(system)), copy.deepcopy(system), copy.copy(system)):
        assert other.settings == system.settings and other is not system
        np.testing.assert_array_equal(other.rollout(demo[-1] + 1.0), system.rollout(demo[-1] + 1.0))


def test_a_system_is_immutable_and_checks_what_it_is_made_of():
    demo = curved_demo(120, 2, seed=1)
    dmp = DMP().fit(demo)
    system = dmp.system_
    with pytest.raises(AttributeError, match="immutable"):
        system.weights = np.zeros_like(system.weights)
    with pytest.raises(dataclasses.FrozenInstanceError):
        system.settings.tau = 2.0
    parts = dict(
        settings=dmp.settings(),
        weights=dmp.weights_,
        start=dmp.start_,
        goal=dmp.goal_,
        n_samples=dmp.n_steps_,
        duration=dmp.duration_,
        centres=dmp.centres_,
        widths=dmp.widths_,
        goal_gate=dmp.goal_gate_,
    )
    bad = [
        ("settings", {"alpha": 1.0}, TypeError, "settings must be a DMPSettings"),
        ("weights", dmp.weights_[:-1], ValueError, "weights must have shape"),
        ("weights", np.full_like(dmp.weights_, np.nan), ValueError, "weights contains NaN"),
        ("start", dmp.start_[:1], ValueError, "start"),
        ("n_samples", 2, ValueError, "n_samples"),
        ("duration", -1.0, ValueError, "duration"),
        ("centres", dmp.centres_ + 1.0, ValueError, "centres must lie in"),
        ("widths", -dmp.widths_, ValueError, "widths must be > 0"),
        ("goal_gate", None, ValueError, "goal_gate is required"),
        ("goal_gate", dmp.goal_gate_[:-1], ValueError, "goal_gate must have"),
    ]
    for name, value, error, match in bad:
        with pytest.raises(error, match=match):
            DMPSystem(**{**parts, name: value})
    for step in (-0.01, float("nan"), np.ones(2)):
        with pytest.raises((ValueError, TypeError), match="step"):
            system.grid(10, step)
    paper = DMP(protocol="paper").fit(demo)
    with pytest.raises(ValueError, match="goal_gate is the learned progress gate"):
        DMPSystem(
            paper.settings(),
            paper.weights_,
            paper.start_,
            paper.goal_,
            paper.n_steps_,
            paper.duration_,
            paper.centres_,
            paper.widths_,
            np.ones(paper.n_steps_),
        )


@pytest.mark.parametrize(
    "change, error, match",
    [
        ({"alpha": -1.0}, ValueError, "alpha"),
        ({"alpha": True}, TypeError, "alpha must be a number"),
        ({"tau": 0.0}, ValueError, "tau"),
        ({"integrator": "rk4"}, ValueError, "integrator"),
        ({"basis": GaussianBasis(13)}, ValueError, "n_kernels .12. must equal the basis's size"),
        ({"basis": object()}, TypeError, "basis must provide Basis's"),
        ({"keep_approach": 1}, TypeError, "keep_approach must be True or False"),
        ({"keep_approach": True}, ValueError, "keep_approach shapes"),
        ({"settle": 0.5}, ValueError, "settle"),
        ({"goal_rate": float("nan")}, ValueError, "goal_rate"),
        ({"widths": "pydmps"}, ValueError, "widths .'pydmps'. must be the basis's width rule"),
    ],
)
def test_settings_refuse_a_bad_field_made_or_replaced(change, error, match):
    with pytest.raises(error, match=match):
        paper_settings(**change)
    with pytest.raises(error, match=match):
        paper_settings().replace(**change)


def test_settings_are_the_estimators_resolution_and_a_value():
    settings = DMP(protocol="paper", n_kernels=12, alpha_phase=1.0).settings()
    assert settings == paper_settings()  # the paper's defaults, written out by hand above
    assert hash(settings) == hash(paper_settings())
    assert settings.replace(tau=2.0) != settings and settings.replace(tau=2.0).tau == 2.0
    assert settings.with_tau(1.0) is settings
    with pytest.raises(TypeError, match="unknown setting"):
        settings.replace(gain=1.0)


def test_settings_are_resolved_again_after_any_change():
    """The cache of resolved settings never serves a changed parameter, a changed type or changed
    limits."""
    dmp = DMP(n_kernels=40)
    first = dmp.settings()
    assert dmp.settings() is first  # resolved once
    dmp.alpha = 30.0
    assert dmp.settings().alpha == 30.0
    dmp.alpha = 1
    assert dmp.settings().alpha == 1.0
    dmp.alpha = True  # equal to 1, but no number
    with pytest.raises(TypeError, match="alpha must be a number"):
        dmp.settings()
    dmp.alpha = None
    assert dmp.settings() == first
    with bidmp.set_limits(max_kernels=20):
        with pytest.raises(ValueError, match="max_kernels"):
            dmp.settings()
    assert dmp.settings() == first
    dmp.tau = 2.0
    assert dmp.settings().tau == 2.0


def test_models_made_alike_share_a_resolution_and_no_other():
    """Fresh models with the same parameters share their resolved settings; one that differs in a
    value, a type, a class or the limits does not, nor does a model with a component of its own
    (which the settings would hold and the user may change)."""
    from bidmp.primitives.canonical import ExponentialPhase
    from bidmp.primitives.dmp import _SHARED_SETTINGS_SIZE

    class Renamed(DMP):
        pass

    first = DMP(n_kernels=40).settings()
    assert DMP(n_kernels=40).settings() is first
    assert DMP(n_kernels=41).settings().n_kernels == 41
    assert DMP(n_kernels=40, alpha=1).settings().alpha == 1.0
    with pytest.raises(TypeError, match="alpha must be a number"):
        DMP(n_kernels=40, alpha=True).settings()  # equal to 1 as a key, but no number
    with bidmp.set_limits(max_kernels=20), pytest.raises(ValueError, match="max_kernels"):
        DMP(n_kernels=40).settings()
    again = DMP(n_kernels=40).settings()  # limits changed and restored: resolved anew
    assert again == first and DMP(n_kernels=40).settings() is again
    assert Renamed(n_kernels=40).settings() is not again
    phase = ExponentialPhase(4.0)
    model = DMP(n_kernels=40, canonical_system=phase)
    own = model.settings()
    assert model.settings() is own  # its own cache still serves it
    assert DMP(n_kernels=40, canonical_system=phase).settings() is not own
    for n in range(2 * _SHARED_SETTINGS_SIZE):  # bounded: the oldest make room
        DMP(n_kernels=50 + n).settings()
    from bidmp.primitives.dmp import _SHARED_SETTINGS

    assert len(_SHARED_SETTINGS) <= _SHARED_SETTINGS_SIZE


def test_a_changed_parameter_still_unfits_the_system():
    demo = curved_demo(120, 2, seed=4)
    dmp = DMP().fit(demo)
    dmp.set_params(alpha=30.0)
    with pytest.raises(NotFittedError, match="alpha"):
        dmp.system_  # noqa: B018 - the property is what is tested
    dmp.set_params(alpha=None, tau=1.5)  # tau may change
    assert dmp.system_.settings.tau == 1.5


# --- structure: no module reaches into another class's private members ----------------------
# Named-tuple methods and scikit-learn's own hook are the one public API spelled with "_".
_PUBLIC_UNDERSCORED = {"_replace", "_fields", "_asdict", "_make", "_get_param_names"}


def _own_names(module_name: str, tree: ast.Module) -> set[str]:
    """The private names a module may use on other objects: those it defines (functions, classes,
    attributes it sets) and every member of the classes it defines, inherited ones included."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
    try:
        module = importlib.import_module(module_name)
    except ImportError:  # a module the check is shown on, not one of the package's
        return names
    for value in vars(module).values():
        if inspect.isclass(value) and value.__module__ == module_name:
            names.update(dir(value))
            names.update(getattr(value, "__slots__", ()))
    return names


def private_reaches(
    root: pathlib.Path = SRC, subpackages=("primitives", "incremental", "extension")
) -> list:
    found = []
    for package in subpackages:
        for path in sorted((root / package).rglob("*.py")):
            parts = path.relative_to(root.parent).with_suffix("").parts
            module_name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            tree = ast.parse(path.read_text())
            own = _own_names(module_name, tree)
            for node in ast.walk(tree):
                if not isinstance(node, ast.Attribute) or not node.attr.startswith("_"):
                    continue
                if node.attr.startswith("__") or node.attr in _PUBLIC_UNDERSCORED:
                    continue
                if isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
                    continue
                if node.attr not in own:
                    found.append(f"{path.relative_to(root)}:{node.lineno} {ast.unparse(node)}")
    return found


# The reaches left, by name, and why: none. The DMP's own (its parameters, grid, rollout
# preparation, training trajectory), the per-step twins, the model-file protocol and the pose
# models' parts all go through public methods now. A new one must be listed here with its reason.
_LEFT: dict[str, str] = {}


def test_the_math_never_reaches_into_another_classs_private_members():
    """Structure guard: the DMP's parts talk through public methods (its system, its settings),
    not through one another's private ones; the reaches left are listed with their reason."""
    found = private_reaches()
    reached = {line.rsplit(".", 1)[1] for line in found}
    assert reached - set(_LEFT) == set(), [
        line for line in found if line.rsplit(".", 1)[1] not in _LEFT
    ]
    assert set(_LEFT) - reached == set(), "no longer reached: drop from _LEFT"


def test_the_private_reach_check_sees_one(tmp_path):
    package = tmp_path / "bidmp" / "primitives"
    package.mkdir(parents=True)
    (tmp_path / "bidmp" / "incremental").mkdir()
    (package / "reach_shown.py").write_text(
        "def f(dmp):\n    return dmp._secret() + dmp._shown\n\n\ndef _shown():\n    pass\n"
    )
    assert private_reaches(tmp_path / "bidmp") == ["primitives/reach_shown.py:2 dmp._secret"]
