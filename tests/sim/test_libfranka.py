"""libfranka in the loop (bidmp.sim.libfranka, bidmp verify --libfranka).

Two kinds of test:

* marked ``libfranka`` (``make franka-check``, CI's libfranka stage; skipped where the side
  environment of ``make franka`` is missing): real streams through pylibfranka to franka-sim —
  generated streams with planted breaches judged the same by bidmp and by libfranka, the job's
  motions on the FR3 accepted by libfranka. These show correctness against real robot software.
* always run: the process handling around the side environment, with a stand-in for its Python
  (a missing environment said so in one line, the side's lines read, a hung side killed with
  everything it started, a side that dies reported). These guard structure.
"""

from __future__ import annotations

import json
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bidmp.sim import libfranka
from bidmp.sim.fci import judge_commands

DATA = Path(__file__).resolve().parents[1] / "data"


def _side_available() -> bool:
    try:
        libfranka.franka_side_environment()
    except libfranka.SideEnvironmentError:
        return False
    return True


needs_side = pytest.mark.skipif(
    not _side_available(), reason="no libfranka side environment here (make franka builds it)"
)


# -- with libfranka ---------------------------------------------------------------------------


def _pairs(families):
    """Each family's (just inside, just outside) streams by bidmp's judge, 0.5 % apart."""
    from fci_streams import bisect, inside

    out = []
    for family in families:

        def passes(q, kind=family.kind):
            verdict = judge_commands(q, "fr3")
            return inside(kind, verdict.ok, (verdict.reflex,))

        low, high = bisect(passes, family, rel=0.005)
        out += [(family, "inside", low), (family, "outside", high)]
    return out


def test_the_threshold_families_sit_where_the_published_tables_put_them():
    """Every limit kind on every joint (tests/fci_streams.py: built from the published tables
    and closed forms, each kind's threshold at factor 1), bisected by bidmp's judge: its
    threshold within 0.5 % of 1; past it the kind's reflex on the family's joint; before it
    accepted (a range stream: rejected for its jump, not for the range)."""
    from fci_streams import LIMIT_KINDS, REFLEXES, families, inside

    generated = families(1, seed=3)
    assert {(f.kind, f.joint) for f in generated} == {
        (kind, joint) for kind in LIMIT_KINDS for joint in range(1, 8)
    }
    for family, side, factor in _pairs(generated):
        assert 0.995 <= factor <= 1.005, (family.kind, family.joint, side, factor)
        verdict = judge_commands(family.at(factor), "fr3")
        if side == "inside":
            assert inside(family.kind, verdict.ok, (verdict.reflex,)), verdict.reason()
        else:
            assert (verdict.reflex, verdict.joint) == (REFLEXES[family.kind], family.joint)


@pytest.mark.libfranka
@needs_side
def test_libfranka_and_bidmp_judge_threshold_pairs_alike():
    """A family of the range, acceleration and jerk limits (on joints 1, 4 and 7: make
    franka-agreement runs 5 of each kind on each joint, 210 of 210 alike), a stream just inside
    and one just outside its threshold (0.5 % apart by bidmp's judge): libfranka accepts what
    bidmp accepts and names the reflex bidmp names. And a flat-velocity family's outside stream
    (35 of 35 alike there): its inside one, 0.2 % under the limit, franka-sim stops now and then
    by the simulated arm's measured velocity, which no judge of commands can know (the guide)."""
    from fci_streams import families

    generated = [
        *families(1, seed=7, joints=(1,), kinds=("range",)),
        *families(1, seed=7, joints=(4,), kinds=("acceleration",)),
        *families(1, seed=7, joints=(7,), kinds=("jerk",)),
    ]
    pairs = _pairs(generated)
    (velocity,) = families(1, seed=7, joints=(3,), kinds=("velocity",))
    pairs.append(_pairs([velocity])[1])
    outcomes = libfranka.stream_fr3([family.at(factor) for family, _, factor in pairs])
    for (family, side, factor), outcome in zip(pairs, outcomes):
        verdict = judge_commands(family.at(factor), "fr3")
        where = (family.kind, family.joint, side, verdict.reason(), outcome.reason())
        assert outcome.phase != "approach", where
        assert verdict.ok == outcome.accepted, where
        if not verdict.ok:
            assert verdict.reflex in outcome.reflexes, where
    assert [side for _, side, _ in pairs].count("outside") == 4


@pytest.mark.libfranka
@needs_side
def test_the_jobs_motions_on_the_fr3_raise_no_reflex_in_libfranka(tmp_path):
    """Every motion of the job on the built-in FR3 cell (two targets: approach, unscrew, retract,
    drop each), written by bidmp job --commands and streamed through libfranka."""
    import bidmp
    from bidmp.cli import main

    cell = json.loads(
        (Path(bidmp.__file__).parent / "data/scenarios/nut-unscrewing.json").read_text()
    )
    cell["robot"]["model"] = "fr3"
    scenario = tmp_path / "fr3.json"
    scenario.write_text(json.dumps(cell))
    out = tmp_path / "job"
    arguments = ["--scenario", str(scenario), "--targets", "3,12", "--no-pictures"]
    assert main(["job", *arguments, "--commands", "--out", str(out)]) == 0
    files = sorted((out / "commands").glob("*.csv"))
    assert len(files) == 8
    assert main(["verify", "--libfranka", *map(str, files)]) == 0


@pytest.mark.libfranka
@needs_side
def test_the_simulators_motions_on_the_fr3_raise_no_reflex_in_libfranka():
    """bidmp sim's motions (every method's that ran, two targets) on the FR3: the 1 kHz commands
    the simulated arm was sent, streamed through libfranka."""
    import bidmp
    from bidmp import sim
    from bidmp.tasks import scenarios

    cell = json.loads(
        (Path(bidmp.__file__).parent / "data/scenarios/nut-unscrewing.json").read_text()
    )
    cell["robot"]["model"] = "fr3"
    report = sim.simulate(
        scenarios.from_dict(cell), ["dmp", "bidmp"], targets=["3", "11"], workers=1, record=True
    )
    commands = [
        target.commands
        for method in report.methods.values()
        for target in method.targets.values()
        if target.ran  # (the plain DMP's to far nut 11 is refused by the contract: not run)
    ]
    assert all(target.ran for target in report.methods["bidmp"].targets.values())
    assert len(commands) >= 3
    outcomes = libfranka.stream_fr3(commands)
    assert all(outcome.accepted for outcome in outcomes), [o.reason() for o in outcomes]


@pytest.mark.libfranka
@needs_side
def test_verify_libfranka_names_libfrankas_reflex(tmp_path, capsys):
    from bidmp.cli import main

    q = np.loadtxt(DATA / "fr3_quintic.csv", delimiter=",", skiprows=1)
    q[400:, 4] += 2e-5  # a jump of 20 µrad on joint 4: a second difference of 20 rad/s² (FR3: 10)
    path = tmp_path / "jump.csv"
    header = "t," + ",".join(f"fr3_joint{i}" for i in range(1, 8))
    np.savetxt(path, q, delimiter=",", header=header, comments="", fmt="%.10g")
    assert main(["verify", "--libfranka", str(path)]) == 3
    out = capsys.readouterr().out
    assert "rejected by libfranka" in out and "velocity_discontinuity at sample 400" in out
    assert "disagrees" not in out


# -- the side environment's handling (a stand-in for its Python) --------------------------------


def _fake_side(tmp_path: Path, body: str) -> Path:
    """A side environment whose Python is the shell script ``body`` (the model an empty file)."""
    venv = tmp_path / "side"
    tmp_path.mkdir(parents=True, exist_ok=True)
    (venv / "bin").mkdir(parents=True)
    python = venv / "bin" / "python"
    python.write_text("#!/bin/sh\n" + body)
    python.chmod(python.stat().st_mode | stat.S_IEXEC)
    (venv / libfranka.SIDE_MODEL_NAME).write_text("")
    return venv


def test_a_missing_side_environment_says_how_to_build_it(tmp_path, monkeypatch, capsys):
    from bidmp.cli import main

    monkeypatch.setenv(libfranka.SIDE_VENV_VARIABLE, str(tmp_path / "nowhere"))
    with pytest.raises(libfranka.SideEnvironmentError, match="make franka"):
        libfranka.stream_fr3([np.zeros((3, 7))])
    assert main(["verify", "--libfranka", str(DATA / "fr3_quintic.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "make franka" in err and "BIDMP_FRANKA_VENV" in err


def test_a_panda_is_not_streamed_to_the_simulated_fr3(capsys):
    from bidmp.cli import main

    assert main(["verify", "--robot", "panda", "--libfranka", str(DATA / "fr3_quintic.csv")]) == 2
    assert "simulates an FR3 only" in capsys.readouterr().err


@pytest.mark.parametrize("bad", [np.zeros((3, 6)), np.full((3, 7), np.nan), np.zeros((0, 7))])
def test_streams_must_be_finite_seven_joint_positions(bad):
    with pytest.raises(ValueError, match=r"streams\[1\]"):
        libfranka.stream_fr3([np.zeros((3, 7)), bad])


def test_the_sides_lines_are_the_outcomes(tmp_path, monkeypatch):
    lines = [
        {"index": 0, "accepted": True, "reflexes": [], "phase": "", "sample": -1, "message": ""},
        {
            "index": 1,
            "accepted": False,
            "reflexes": ["joint_motion_generator_velocity_discontinuity"],
            "phase": "motion",
            "sample": 12,
            "message": "m",
        },
    ]
    body = "".join(f"echo '{json.dumps(line)}'\n" for line in lines)
    monkeypatch.setenv(libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path, body)))
    first, second = libfranka.stream_fr3([np.zeros((3, 7)), np.zeros((4, 7))])
    assert first.accepted and first.reason() == ""
    assert not second.accepted and second.sample == 12 and second.phase == "motion"
    assert "joint_motion_generator_velocity_discontinuity at sample 12" in second.reason()


def test_a_side_that_stops_short_is_an_error_not_a_verdict(tmp_path, monkeypatch):
    line = {"index": 0, "accepted": True, "reflexes": [], "phase": "", "sample": -1, "message": ""}
    body = f"echo '{json.dumps(line)}'\necho 'server exited' >&2\nexit 1\n"
    monkeypatch.setenv(libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path, body)))
    with pytest.raises(libfranka.SideEnvironmentError, match="exit 1 after 1 of 2.*server exited"):
        libfranka.stream_fr3([np.zeros((3, 7)), np.zeros((3, 7))])


def test_a_hung_side_is_killed_with_what_it_started(tmp_path, monkeypatch):
    """The side's own child (its server) goes too: the whole process group is killed."""
    pids = tmp_path / "pids"
    body = f"sleep 300 &\necho $! > {pids}\necho $$ >> {pids}\nwait\n"
    monkeypatch.setenv(libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path, body)))
    with pytest.raises(libfranka.SideEnvironmentError, match="did not finish 1 streams within 1 s"):
        libfranka.stream_fr3([np.zeros((3, 7))], timeout_s=1.0)
    for pid in map(int, pids.read_text().split()):
        assert not _running(pid), pid


def _running(pid: int) -> bool:
    """Whether ``pid`` still runs (a killed process nobody has reaped yet is a zombie: not running)."""
    import time

    for _ in range(50):  # the kill is delivered at once, but its exit is the kernel's business
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except (FileNotFoundError, ProcessLookupError):
            return False
        if state in ("Z", "X"):
            return False
        time.sleep(0.02)
    return True


def test_the_side_script_imports_nothing_of_bidmp():
    """It runs under the side environment's NumPy 1.26, where bidmp is not installed."""
    source = Path(libfranka.SIDE_SCRIPT).read_text()
    assert "bidmp" not in "".join(
        line for line in source.splitlines() if line.lstrip().startswith(("import", "from"))
    )
    result = subprocess.run(
        [sys.executable, "-I", str(libfranka.SIDE_SCRIPT), "--help"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0 and "build-model" in result.stdout


def _line(accepted: bool, **fields) -> str:
    record = {"index": 0, "accepted": accepted, "reflexes": [], "phase": "", "sample": -1}
    record.update(message="", **fields)
    return f"echo '{json.dumps(record)}'\n"


def test_verifys_exit_status_is_libfrankas_verdict(tmp_path, monkeypatch, capsys):
    """With --libfranka the side's verdict decides (a stand-in side here): all accepted, exit 0;
    one rejected, exit 3 with its reflex, and bidmp's own (accepting) judge printed beside it."""
    from bidmp.cli import main

    motion = str(DATA / "fr3_quintic.csv")
    monkeypatch.setenv(
        libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path / "a", _line(True) * 2))
    )
    assert main(["verify", "--libfranka", motion, motion]) == 0
    out = capsys.readouterr().out
    assert out.count("accepted by libfranka: ") == 2 and "2 of 2 motions accepted" in out
    assert "disagrees" not in out
    rejected = _line(
        False,
        reflexes=["joint_motion_generator_velocity_discontinuity"],
        phase="motion",
        sample=7,
        retries=1,
    )
    monkeypatch.setenv(
        libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path / "b", _line(True) + rejected))
    )
    assert main(["verify", "--libfranka", motion, motion]) == 3
    out = capsys.readouterr().out
    assert "rejected by libfranka" in out and "velocity_discontinuity at sample 7" in out
    assert "bidmp's FCI judge disagrees: accepted" in out and "1 of 2 motions accepted" in out
    assert "streamed 2 times" in out
    monkeypatch.setenv(libfranka.SIDE_VENV_VARIABLE, str(_fake_side(tmp_path / "c", _line(True))))
    assert main(["verify", "--libfranka", motion]) == 0  # one motion: no count of them
    assert "motions accepted" not in capsys.readouterr().out
