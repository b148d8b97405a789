"""A DMP is composed of components: its canonical system (phase) and its forcing term's basis are
objects with small protocols, so a new phase or basis plugs in without a new DMP.

The rhythmic phase and von Mises basis here are stand-ins written for the test (the periodic DMP
proper is its own feature); what they show is that the DMP's fit, rollout, trajectory, stepper and
grid queries all go through the components and nothing assumes the decaying phase.
"""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.base import clone

from bidmp import DMP
from bidmp.io import load_model, save_model
from bidmp.primitives import CanonicalSystem, ExponentialPhase, GaussianBasis
from bidmp.primitives.forcing import Basis


class CyclePhase:
    """Stand-in rhythmic canonical system: the phase is the fraction of a cycle, advancing at
    ``frequency`` cycles per unit of normalised time and wrapping at 1."""

    initial = 0.0

    def __init__(self, frequency: float) -> None:
        self.frequency = frequency

    def __eq__(self, other) -> bool:
        return type(other) is CyclePhase and other.frequency == self.frequency

    def __hash__(self) -> int:
        return hash(self.frequency)

    def grid(self, n_steps, step, tau):
        return self.at(np.arange(n_steps), step, tau)

    def at(self, samples, step, tau):
        return np.mod(self.frequency * step / tau * np.asarray(samples, dtype=float), 1.0)

    def advance(self, phase, step, tau):
        return (phase + self.frequency * step / tau) % 1.0

    def check_step(self, step, tau):
        pass

    def check_span(self, span):
        pass

    def as_phase(self, phase, name="phase"):
        phase = np.asarray(phase, dtype=float).reshape(-1)
        if np.any((phase < 0.0) | (phase >= 1.0)):
            raise ValueError(f"{name} must lie in [0, 1)")
        return phase


class VonMisesBasis:
    """Stand-in periodic basis: ``size`` normalised von Mises functions over one cycle."""

    def __init__(self, size: int, concentration: float = 8.0) -> None:
        self.size = size
        self.concentration = concentration

    def place(self, canonical, n_steps, step):
        return (np.arange(self.size) + 0.5) / self.size, np.full(self.size, self.concentration)

    def rows(self, phase, centres, widths):
        angle = 2.0 * np.pi * (np.asarray(phase)[:, None] - centres[None, :])
        psi = np.exp(widths * (np.cos(angle) - 1.0))
        return psi / psi.sum(axis=1, keepdims=True)

    def row(self, phase, centres, widths):
        return self.rows(np.array([phase]), centres, widths)


CYCLES = 3
AMPLITUDE = 0.05  # m


def _rhythmic_demonstration(n_samples=600, duration=1.5):
    """Three cycles of a two-harmonic motion that starts and ends at rest at the origin."""
    t = np.linspace(0.0, duration, n_samples)
    angle = 2.0 * np.pi * CYCLES * t / duration
    y = np.column_stack(
        [
            AMPLITUDE * (1.0 - np.cos(angle)),
            0.4 * AMPLITUDE * (1.0 - np.cos(2.0 * angle)),
        ]
    )
    return t, y


def _rhythmic_dmp(n_samples=600):
    return DMP(
        protocol="paper",
        integrator="exact",
        regression="ridge",
        goal_rate=2.0,
        canonical_system=CyclePhase(CYCLES * n_samples / (n_samples - 1)),
        forcing_basis=VonMisesBasis(40),
    )


def test_the_stand_ins_meet_the_protocols_and_the_defaults_are_components():
    """Structure guard: the protocols name what a DMP asks; the default DMP's parts are the
    exponential phase and the Gaussian basis."""
    assert isinstance(CyclePhase(1.0), CanonicalSystem)
    assert isinstance(VonMisesBasis(5), Basis)
    params = DMP().settings()
    assert params.canonical_system == ExponentialPhase(4.0, exact=True)
    assert params.basis == GaussianBasis(100)


def test_a_rhythmic_phase_and_basis_plug_in_and_reproduce_a_periodic_motion():
    t, y = _rhythmic_demonstration()
    dmp = _rhythmic_dmp().fit(y, t, units="m")
    # The phase is the stand-in's: it wraps, which no decaying phase does.
    phase = dmp.phase()
    assert phase[0] == 0.0
    assert np.count_nonzero(np.diff(phase) < 0.0) >= CYCLES - 1
    np.testing.assert_array_equal(
        phase, CyclePhase(dmp.canonical_system.frequency).grid(dmp.default_n_steps(), dmp.dt_, 1.0)
    )
    motion = dmp.trajectory()
    reproduced = np.interp(t, motion.t, motion.y[:, 0]), np.interp(t, motion.t, motion.y[:, 1])
    error = np.max(np.abs(np.column_stack(reproduced) - y))
    assert error < 0.02 * AMPLITUDE, error


def test_the_rhythm_goes_on_past_the_demonstration():
    """The periodic forcing term keeps the motion cycling: a rollout twice as long repeats the
    demonstration in its second half (the demonstration's own periodic continuation)."""
    t, y = _rhythmic_demonstration()
    dmp = _rhythmic_dmp().fit(y, t, units="m")
    n = dmp.n_steps_
    longer = dmp.rollout(n_steps=2 * n - 1)
    # sample n - 1 + l is one demonstration later than sample l (the phase advanced CYCLES cycles)
    continuation = longer[n - 1 : 2 * n - 1]
    error = np.max(np.abs(continuation - longer[:n]))
    assert error < 0.015 * AMPLITUDE, error


def test_the_stepper_runs_the_components_sample_for_sample():
    t, y = _rhythmic_demonstration()
    dmp = _rhythmic_dmp().fit(y, t, units="m")
    motion = dmp.trajectory()
    stepper = dmp.stepper()
    dt = float(motion.t[1] - motion.t[0])
    stepped = np.array([stepper.step(dt)[0] for _ in range(motion.t.shape[0])])
    np.testing.assert_allclose(stepped, motion.y, atol=1e-9 * np.ptp(y), rtol=0)


def test_a_goal_system_that_looks_up_by_a_decaying_phase_is_refused_for_a_wrapping_one():
    t, y = _rhythmic_demonstration()
    dmp = _rhythmic_dmp().set_params(protocol="robot", goal_rate=None, integrator=None)
    with pytest.raises(ValueError, match="progress gate.*goal_rate"):
        dmp.fit(y, t)


def test_components_and_the_parameters_that_build_the_defaults_are_not_both_given():
    t, y = _rhythmic_demonstration()
    with pytest.raises(ValueError, match="canonical_system or alpha_phase"):
        DMP(canonical_system=CyclePhase(2.0), alpha_phase=3.0).fit(y, t)
    with pytest.raises(ValueError, match="forcing_basis or n_kernels"):
        DMP(forcing_basis=VonMisesBasis(5), n_kernels=5).fit(y, t)
    with pytest.raises(ValueError, match="regression='lwr'"):
        DMP(protocol="paper", forcing_basis=VonMisesBasis(5)).fit(y, t)
    with pytest.raises(TypeError, match="canonical_system must provide.*lacks advance"):
        DMP(canonical_system=object()).fit(y, t)


def test_given_default_components_are_the_default_dmp(tmp_path):
    """The components built from the parameters and the same components given explicitly are one
    model: the same trajectory to the last bit, and the explicit ones survive a model file."""
    t, y = _rhythmic_demonstration()
    y = y + np.linspace(0.0, 0.1, y.shape[0])[:, None]  # a discrete motion
    implicit = DMP().fit(y, t)
    explicit = DMP(
        canonical_system=ExponentialPhase(4.0, exact=True), forcing_basis=GaussianBasis(100)
    ).fit(y, t)
    np.testing.assert_array_equal(explicit.trajectory().y, implicit.trajectory().y)
    path = tmp_path / "explicit.npz"
    save_model(explicit, path)
    loaded = load_model(path)
    assert loaded.forcing_basis == GaussianBasis(100)
    np.testing.assert_array_equal(loaded.trajectory().y, implicit.trajectory().y)
    cloned = clone(explicit)
    assert cloned.canonical_system == explicit.canonical_system


def test_a_model_file_names_only_bidmps_components(tmp_path):
    t, y = _rhythmic_demonstration()
    dmp = _rhythmic_dmp().fit(y, t, units="m")
    with pytest.raises(ValueError, match="bidmp's own components.*CyclePhase"):
        save_model(dmp, tmp_path / "rhythmic.npz")


def test_a_fit_caches_its_learned_gate_as_the_phase_lookup_gives_it():
    """On the grid it was learned on and one sample past it, the learned progress gate is what the
    lookup by phase (ProgressGate.on_grid) gives — which a fit no longer builds for its cached
    grid; a phase rising again past the grid is left to the lookup, and one that does not decay is
    refused as the lookup refuses it."""
    from bidmp.primitives.goals import ProgressGate, _gate_past_training

    rng = np.random.default_rng(21)
    for n_train in (2, 3, 50, 1100):
        canonical = ExponentialPhase(float(rng.uniform(1.0, 8.0)), exact=True)
        phase = canonical.grid(n_train + 1, 1.0 / n_train, 1.0)
        gate = rng.normal(size=n_train)
        lookup = ProgressGate(phase[:-1], gate).on_grid(phase, 1.0 / n_train, 1.0, True)
        shortcut = _gate_past_training(gate, phase, canonical)
        assert np.array_equal(shortcut, lookup)
    rising = np.array([1.0, 0.5, 0.2, 0.3])
    assert _gate_past_training(np.ones(3), rising, canonical) is None
    with pytest.raises(ValueError, match="must decay"):
        _gate_past_training(np.ones(3), np.array([1.0, 1.0, 0.5, 0.2]), canonical)
