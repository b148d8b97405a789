"""One pipeline whatever the flags: what ``bidmp sim`` and ``bidmp job`` send to the arm is the
motion the evaluation judged and repaired, with or without pictures, the viewer, workers or a
subset of the targets.

The commands are captured where they are executed (every 1 ms joint command the arm was sent,
``record=True`` forced on the library call the command makes) and compared bit for bit between
runs that differ only in an output flag. A flag that changed what runs (the viewer once took the
motions from an evaluation without the scene, so a motion the contract had lifted over a post ran
unrepaired, into it) fails here. The comparisons are of the code with itself: they guard the
wiring, not the motions' correctness, which the contract's own tests judge."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from bidmp.cli import main

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
TWO_POSTS = str(DATA / "two_posts.json")  # posts between the nuts: the far motions are repaired


def _recording(monkeypatch, module, name: str) -> dict:
    """Replace ``module.name`` (the library call a command makes) by the same call with
    ``record=True``; the returned dict receives its result under "result"."""
    captured = {}
    original = getattr(module, name)

    def recording(*args, **options):
        options["record"] = True
        captured["result"] = original(*args, **options)
        return captured["result"]

    monkeypatch.setattr(module, name, recording)
    return captured


def _sim_commands(monkeypatch, tmp_path, *flags) -> tuple[dict, dict]:
    """``bidmp sim`` on the two-post cell with ``flags``: (method, label) -> the joint commands
    it executed, and -> the repair the evaluation made."""
    from bidmp.sim import run

    captured = _recording(monkeypatch, run, "simulate")
    out = tmp_path / "-".join(flag.strip("-") for flag in flags if flag.startswith("--"))
    code = main(["sim", "--scenario", TWO_POSTS, "--out", str(out), *flags])
    assert code in (0, 3), code
    result = captured["result"]
    commands, repairs = {}, {}
    for method, outcome in result.methods.items():
        for label, target in outcome.targets.items():
            commands[(method, label)] = target.commands
            repairs[(method, label)] = target.repair
    return commands, repairs


def _assert_same(first: dict, second: dict) -> None:
    assert first.keys() == second.keys()
    for key, commands in first.items():
        other = second[key]
        if commands is None or other is None:  # not run in either (refused, unreachable)
            assert commands is None and other is None, key
            continue
        assert commands.shape == other.shape and np.array_equal(commands, other), key


def test_bidmp_sim_executes_the_same_commands_with_and_without_output_flags(monkeypatch, tmp_path):
    """On the PyBullet arm (pictures and the viewer's recording are its own): one worker with
    pictures and no other flag, against the viewer with two workers and no pictures (every
    output flag changed at once, in one run: the suite's time)."""
    pytest.importorskip("pybullet")
    targets = ["--targets", "12"]
    plain, repairs = _sim_commands(monkeypatch, tmp_path, *targets, "--workers", "1")
    # the far motion is repaired (lifted over the posts): the case a flag once left unrepaired
    assert repairs[("bidmp", "12")], repairs
    flags = ["--view", "--workers", "2", "--no-pictures"]
    other, other_repairs = _sim_commands(monkeypatch, tmp_path, *targets, *flags)
    assert other_repairs == repairs, flags
    _assert_same(plain, other)


def test_a_subset_of_the_targets_runs_what_the_whole_run_runs_for_them(monkeypatch, tmp_path):
    """The targets of a subset are executed as in a run of every target (the evaluation that
    learns and repairs them sees every target either way)."""
    every, _ = _sim_commands(monkeypatch, tmp_path, "--backend", "kinematic", "--no-pictures")
    subset, _ = _sim_commands(
        monkeypatch, tmp_path, "--backend", "kinematic", "--targets", "12,5", "--view"
    )  # and the backend's name given, the ideal arm: the same pipeline
    _assert_same({key: every[key] for key in subset}, subset)


def test_bidmp_job_executes_the_same_commands_with_and_without_output_flags(monkeypatch, tmp_path):
    from bidmp.sim import job

    def commands(*flags) -> dict:
        captured = _recording(monkeypatch, job, "run_job")
        out = tmp_path / ("job" + "".join(flags))
        code = main(
            ["job", "--scenario", TWO_POSTS, "--targets", "3,12", "--backend", "kinematic"]
            + ["--out", str(out), *flags]
        )
        assert code in (0, 3), code
        runs = {}
        for target in captured["result"].targets:
            for k, phase in enumerate(target.phases):
                runs[(target.label, k, phase.name)] = getattr(phase, "commands", None)
        assert runs, "the job ran no phase"
        return runs

    plain = commands()
    assert any(value is not None for value in plain.values())
    for flags in (["--view"], ["--no-pictures"]):
        _assert_same(plain, commands(*flags))


def test_simulate_refuses_motions_the_contract_did_not_judge_and_repair():
    """A report evaluated without the scene (or without repairs) is refused, naming what is
    executed instead; the report simulate makes itself is the one it hands back."""
    from bidmp import sim
    from bidmp.tasks import evaluate, scenarios

    nut = scenarios.load("nut-unscrewing")
    unjudged = evaluate(nut, ["bidmp"], geometry=False)
    with pytest.raises(ValueError, match=r"report: .*execution_report"):
        sim.simulate(nut, ["bidmp"], targets=["3"], report=unjudged, backend="kinematic")
    unrepaired = evaluate(nut, ["bidmp"], repair=False)
    with pytest.raises(ValueError, match=r"report: .*execution_report"):
        sim.simulate(nut, ["bidmp"], targets=["3"], report=unrepaired, backend="kinematic")
    with pytest.raises(TypeError, match="report must be"):
        sim.simulate(nut, ["bidmp"], targets=["3"], report={"bidmp": 1}, backend="kinematic")
    result = sim.simulate(nut, ["bidmp"], targets=["3"], backend="kinematic")
    assert result.evaluation.settings == sim.execution_settings(nut)
    assert result.evaluation.settings["repair"] and result.evaluation.settings["allowance"] > 0


def test_what_the_simulator_repairs_follows_the_scenarios_approach():
    """A scenario that takes the paper's approach (its skills grown blind, no repairs: the paper's
    protocol) runs its motions as they are; one that keeps the approach runs them repaired. No
    scene, no simulator."""
    from bidmp import sim
    from bidmp.tasks import scenarios

    nut = scenarios.load(TWO_POSTS)
    assert sim.execution_settings(nut)["repair"] is True
    paper = nut.replace(extension={**nut.extension.flat, "approach": "paper"})
    assert sim.execution_settings(paper) == {
        "geometry": True,
        "repair": False,
        "allowance": pytest.approx(0.5),
    }  # nothing repaired: the links start no repair either (no "arm")
    spec = {k: v for k, v in nut.spec.items() if k not in ("scene", "job", "robot")}
    bare = scenarios.from_dict(spec)
    assert sim.execution_settings(bare)["geometry"] is False
    assert sim.execution_settings(bare)["repair"] is False
