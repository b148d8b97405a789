"""The FCI's limits as the judge of 1 kHz joint commands (bidmp.sim.fci), against independent
references: the published tables typed here (a structure guard: a typo in the module fails it),
a plain per-sample loop written from libfranka's description of the check (the vectorised judge
must give the same first breach on every stream, planted breaks of each kind at random samples
and joints included), and the closed form of a DMP's first jerk from rest."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bidmp.sim.fci import FCI_LIMITS, judge_commands, match_joint_names

DT = 1e-3


def test_the_tables_are_the_published_ones():
    """Typed from the sources the module names (Franka's control parameters and libfranka 0.9 for
    the Panda; the FR3's URDF and libfranka >= 0.10 for the FR3)."""
    panda, fr3 = FCI_LIMITS["panda"], FCI_LIMITS["fr3"]
    assert panda.upper == (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973)
    assert panda.lower == (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973)
    assert panda.velocity == (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61)
    assert panda.acceleration == (15, 7.5, 10, 12.5, 15, 20, 20)
    assert panda.jerk == (7500, 3750, 5000, 6250, 7500, 10000, 10000)
    assert fr3.lower[5] == 0.54092 and fr3.upper[5] == 4.5205  # joint 6: 0.54-4.52 rad
    assert fr3.velocity == (2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26)
    assert fr3.acceleration == (10,) * 7 and fr3.jerk == (5000,) * 7
    assert fr3.deceleration == (6.0, 2.585, 3.5, 4.0, 17.0, 5.5, 17.0)


def reference(q: np.ndarray, robot: str):
    """The check, sample by sample and joint by joint, as libfranka describes it: the arm at rest
    at q[0] before the first command and held at q[-1] for three after the last; at each sample
    the position, then the acceleration, the velocity (against the position-based limits where
    the arm has them: libfranka's, at the previous command, less its 1e-3 rad/s tolerance, never
    past a standstill) and the jerk."""
    limits = FCI_LIMITS[robot]
    previous = [list(q[0])] * 3
    for sample, row in enumerate(list(q) + [q[-1]] * 3):
        history = previous[-3:] + [list(row)]
        for quantity in ("position", "acceleration", "velocity", "jerk"):
            for joint in range(7):
                p3, p2, p1, p0 = (h[joint] for h in history)
                v0, v1, v2 = (p0 - p1) / DT, (p1 - p2) / DT, (p2 - p3) / DT
                a0, a1 = (v0 - v1) / DT, (v1 - v2) / DT
                j0 = (a0 - a1) / DT
                if quantity == "position":
                    bad = not limits.lower[joint] <= p0 <= limits.upper[joint]
                elif quantity == "velocity":
                    v_max = limits.velocity[joint]
                    if limits.velocity_offset is None:
                        low, high = -v_max, v_max
                    else:
                        offset, dec = limits.velocity_offset[joint], limits.deceleration[joint]
                        up = math.sqrt(max(0.0, 2 * dec * (limits.upper[joint] - p1)))
                        down = math.sqrt(max(0.0, 2 * dec * (p1 - limits.lower[joint])))
                        high = max(0.0, min(v_max, max(0.0, -offset + up)) - 1e-3)
                        low = min(0.0, max(-v_max, min(0.0, offset - down)) + 1e-3)
                    bad = not low <= v0 <= high
                elif quantity == "acceleration":
                    bad = abs(a0) > limits.acceleration[joint]
                else:
                    bad = abs(j0) > limits.jerk[joint]
                if bad:
                    return quantity, joint + 1, sample
        previous.append(list(row))
    return None


def smooth_move(rng, robot: str, n: int) -> np.ndarray:
    """A quintic rest-to-rest move between random joint positions well inside the ranges."""
    limits = FCI_LIMITS[robot]
    lower, upper = np.array(limits.lower), np.array(limits.upper)
    span = upper - lower
    start = lower + span * rng.uniform(0.3, 0.7, 7)
    goal = start + span * rng.uniform(-0.1, 0.1, 7)
    s = np.linspace(0.0, 1.0, n)[:, None]
    return start + (goal - start) * (10 * s**3 - 15 * s**4 + 6 * s**5)


@pytest.mark.parametrize("robot", ["panda", "fr3"])
def test_the_judge_finds_the_first_breach_the_plain_loop_finds(robot):
    rng = np.random.default_rng(5 if robot == "fr3" else 6)
    kinds = ("none", "position", "velocity", "acceleration", "jerk")
    seen = set()
    for index in range(50):  # (make fci-agreement-style long runs: more streams, same check)
        q = smooth_move(rng, robot, int(rng.integers(300, 1200)))
        kind = kinds[index % len(kinds)]
        joint, sample = int(rng.integers(7)), int(rng.integers(5, len(q) - 5))
        size = rng.uniform(0.5, 2.0)  # around the threshold: half of it to twice it
        limits = FCI_LIMITS[robot]
        if kind == "position":
            q[sample:, joint] += (limits.upper[joint] - q[sample, joint]) * (1.0 + 0.01 * size)
        elif kind == "velocity":  # an acceleration of size x half its limit, switched on over
            # 20 ms (its jerk within every limit) and held: the velocity grows past its limit
            sample = 5 + sample % 50
            t = np.arange(1, len(q) - sample + 1) * DT
            pushed = 0.5 * size * limits.acceleration[joint] * np.minimum(1.0, t / 0.02)
            q[sample:, joint] += np.cumsum(np.cumsum(pushed) * DT) * DT
        elif kind == "acceleration":
            q[sample:, joint] += (
                0.5
                * limits.acceleration[joint]
                * size
                * (np.arange(1, len(q) - sample + 1) * DT) ** 2
            )
        elif kind == "jerk":
            q[sample:, joint] += (
                limits.jerk[joint] * size * DT**3 / 6 * np.arange(1, len(q) - sample + 1) ** 3
            )
        verdict = judge_commands(q, robot)
        expected = reference(q, robot)
        if expected is None:
            assert verdict.ok, (index, kind, verdict.reason())
        else:
            assert (verdict.quantity, verdict.joint, verdict.sample) == expected, (index, kind)
            seen.add(verdict.quantity)
    assert seen == {"position", "velocity", "acceleration", "jerk"}  # every check was reached


def test_a_dmp_from_rest_is_rejected_by_the_fr3_on_its_first_jerk():
    """A plain DMP's spring (α_z = 25, β_z = 6.25) started at rest 0.3 rad from its goal on joint
    4, τ = 3 s: its first acceleration is α_z β_z Δq / τ², so its first jerk α_z β_z Δq / (τ² dt)
    = 5 208 rad/s³: over the FR3's 5 000, under the Panda's 6 250 for that joint."""
    alpha, beta, tau, gap = 25.0, 6.25, 3.0, 0.3
    start = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.8])
    goal = start + np.array([0, 0, 0, gap, 0, 0, 0])
    y, v, rows = start.copy(), np.zeros(7), [start.copy()]
    for _ in range(2000):  # Euler at 1 kHz, no forcing term: the spring alone
        a = (alpha * (beta * (goal - y) - tau * v)) / tau**2
        v = v + a * DT
        y = y + v * DT
        rows.append(y.copy())
    q = np.array(rows)
    first_jerk = alpha * beta * gap / (tau**2 * DT)
    fr3 = judge_commands(q, "fr3")
    assert fr3.reflex == "joint_motion_generator_acceleration_discontinuity"
    assert (fr3.joint, fr3.sample) == (4, 1)
    assert fr3.value == pytest.approx(first_jerk, rel=1e-9) and fr3.bound == 5000.0
    assert judge_commands(q, "panda").ok


def test_the_fr3_velocity_limit_falls_towards_a_joint_stop():
    """Position-based limits: joint 1 at 0.05 rad from its upper stop may move towards it at
    most sqrt(2 · 6 · 0.05) - 0.3 - 0.001 rad/s (libfranka's tolerance cut), far under its
    2.62."""
    limits = FCI_LIMITS["fr3"]
    q = np.array(limits.lower) * 0.0 + np.array([2.7001, 0, 0, -1.5, 0, 2.0, 0])
    lowest, highest = limits.velocity_bounds(q[None])
    assert highest[0, 0] == pytest.approx(math.sqrt(2 * 6.0 * 0.05) - 0.3 - 1e-3, rel=1e-12)
    assert lowest[0, 0] == pytest.approx(-2.62 + 1e-3, rel=1e-12)


def test_joint_names_are_matched_to_the_robots_and_others_refused():
    order = match_joint_names([f"fr3_joint{i}" for i in (3, 1, 2, 4, 5, 6, 7)], "fr3")
    assert order.tolist() == [1, 2, 0, 3, 4, 5, 6]
    with pytest.raises(ValueError, match="'panda_joint1' is not one of the fr3's"):
        match_joint_names([f"panda_joint{i}" for i in range(1, 8)], "fr3")
    with pytest.raises(ValueError, match="no column for fr3_joint7"):
        match_joint_names([f"fr3_joint{i}" for i in range(1, 7)], "fr3")
    with pytest.raises(ValueError, match="q must have 7 columns"):
        judge_commands(np.zeros((5, 6)), "panda")


def test_bidmp_verify_accepts_a_smooth_joint_motion_and_names_a_planted_step(tmp_path, capsys):
    """The command on what 'bidmp rollout --rate 1000' writes of a joint model: exit 0; the same
    file with a 2 mrad step on joint 6 at sample 500: exit 3, one line naming the reflex (a 2 rad/s
    velocity jump in one cycle: the velocity discontinuity), the joint and the sample; a 100 Hz
    file and a Panda's joints given to the FR3: exit 2, one line."""
    from bidmp.cli import main

    t = np.linspace(0.0, 2.0, 200)
    names = [f"fr3_joint{i}" for i in range(1, 8)]
    s = (t / t[-1])[:, None]
    start = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.9, 0.8])
    joints = start + 0.4 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    demo = tmp_path / "joints.csv"
    np.savetxt(
        demo,
        np.column_stack([t, joints]),
        delimiter=",",
        header="t," + ",".join(names),
        comments="",
    )
    assert main(["fit", str(demo), "-o", str(tmp_path / "j.npz")]) == 0
    motion = tmp_path / "motion.csv"
    assert main(["rollout", str(tmp_path / "j.npz"), "--rate", "1000", "-o", str(motion)]) == 0
    capsys.readouterr()
    assert main(["verify", str(motion), "--robot", "fr3"]) == 0
    assert capsys.readouterr().out.startswith("accepted:")
    lines = [line for line in motion.read_text().splitlines() if not line.startswith("#")]
    column = lines[0].split(",").index("fr3_joint6")
    rows = [line.split(",") for line in lines[1:]]
    for row in rows[500:]:
        row[column] = repr(float(row[column]) + 0.002)
    stepped = tmp_path / "stepped.csv"
    stepped.write_text("\n".join([lines[0]] + [",".join(row) for row in rows]) + "\n")
    assert main(["verify", str(stepped), "--robot", "fr3"]) == 3
    out = capsys.readouterr().out.strip()
    assert out.startswith(f"rejected: {stepped}: joint_motion_generator_velocity_"), out
    assert "joint 6" in out and "sample 500" in out
    # several files: one line each and a count; any rejection is exit 3
    assert main(["verify", str(motion), str(stepped)]) == 3
    out = capsys.readouterr().out.strip().splitlines()
    assert out[0].startswith("accepted:") and out[1].startswith("rejected:")
    assert out[2] == "1 of 2 motions accepted"
    slow = tmp_path / "slow.csv"
    assert main(["rollout", str(tmp_path / "j.npz"), "--rate", "100", "-o", str(slow)]) == 0
    capsys.readouterr()
    assert main(["verify", str(slow)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "roll it out at 1000 Hz" in err[0]
    assert main(["verify", str(motion), "--robot", "panda"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'fr3_joint1' is not one of the panda's" in err[0]


def test_a_step_is_a_velocity_discontinuity_even_where_it_passes_the_velocity_limit():
    """A jump of 50 mrad in one cycle on each joint in turn, mid-range: a velocity of 50 rad/s
    (past every velocity limit) and an acceleration of 5e4 rad/s² in the same sample. The robot
    names a step by the velocity's jump (franka-sim, from the hardware; 7 of 7 joints in make
    franka-agreement's range streams), not by the velocity limit. Landing past a stop, the
    range is named."""
    fr3 = FCI_LIMITS["fr3"]
    middle = (np.array(fr3.lower) + np.array(fr3.upper)) / 2
    for joint in range(7):
        q = np.tile(middle, (40, 1))
        q[20:, joint] += 0.05
        verdict = judge_commands(q, "fr3")
        assert verdict.reflex == "joint_motion_generator_velocity_discontinuity", verdict.reason()
        assert (verdict.joint, verdict.sample) == (joint + 1, 20)
        assert verdict.value == pytest.approx(0.05 / DT**2, rel=1e-6)
        q = np.tile(middle, (40, 1))
        q[:, joint] = fr3.upper[joint] - 0.03
        q[20:, joint] = fr3.upper[joint] + 1e-4
        verdict = judge_commands(q, "fr3")
        assert verdict.reflex == "joint_motion_generator_position_limits_violation"
        assert (verdict.joint, verdict.sample) == (joint + 1, 20)


# libfranka >= 0.10's rate_limiting.h, computeUpperLimitsJointVelocity and its lower twin, typed
# as published there (2 · deceleration folded in): (cap, offset, 2 · deceleration, upper, lower)
_LIBFRANKA_ENVELOPE = (
    (2.62, 0.30, 12.0, 2.75010, -2.750100),
    (2.62, 0.20, 5.17, 1.79180, -1.791800),
    (2.62, 0.20, 7.00, 2.90650, -2.906500),
    (2.62, 0.30, 8.00, -0.1458, -3.048100),
    (5.26, 0.35, 34.0, 2.81010, -2.810100),
    (4.18, 0.35, 11.0, 4.52050, 0.54092),
    (5.26, 0.35, 34.0, 3.01960, -3.019600),
)


def _within_libfrankas_envelope(q: np.ndarray, joint: int) -> bool:
    """Every step of ``joint`` in ``q`` (at rest before and after) within libfranka's limits,
    evaluated at the previous command (its rate limiter's ``q_d``), less its 1e-3 tolerance."""
    cap, offset, twice, upper, lower = _LIBFRANKA_ENVELOPE[joint]
    path = np.concatenate([[q[0, joint]] * 3, q[:, joint], [q[-1, joint]] * 3])
    for previous, now in zip(path[:-1], path[1:]):
        velocity = (now - previous) / DT
        high = min(cap, max(0.0, -offset + math.sqrt(max(0.0, twice * (upper - previous))))) - 1e-3
        low = max(-cap, min(0.0, offset - math.sqrt(max(0.0, twice * (previous - lower))))) + 1e-3
        if not min(low, 0.0) <= velocity <= max(high, 0.0):
            return False
    return True


def test_the_fr3s_position_based_velocity_limits_are_libfrankas_at_the_previous_command():
    """Moves braking towards a stop on each joint, scaled until they just touch its position-based
    velocity limit: the scale at which bidmp's judge starts rejecting is the one at which
    libfranka's published limits (typed above, a plain loop) are first passed, to 1e-5."""
    from fci_streams import bisect, families

    for family in families(2, seed=11, kinds=("position-based velocity",)):
        ours = bisect(lambda q: judge_commands(q, "fr3").ok, family, rel=1e-7)
        theirs = bisect(
            lambda q, j=family.joint - 1: _within_libfrankas_envelope(q, j), family, rel=1e-7
        )
        assert ours[0] == pytest.approx(theirs[0], rel=1e-5), (family.joint, family.label)
        verdict = judge_commands(family.at(ours[1]), "fr3")
        assert (verdict.quantity, verdict.joint) == ("velocity", family.joint)


def test_the_edges_of_the_check():
    """Where a bound is reached and not passed, and the signs: a joint held exactly at its stop is
    within its range; a breach downwards (negative acceleration, negative jerk) is one; beyond a
    stop the FR3's velocity bound towards it is a standstill; near the lower stop the bound
    towards it falls as it does towards the upper one."""
    limits = FCI_LIMITS["panda"]
    held = np.tile(np.array(limits.upper), (20, 1))
    assert judge_commands(held, "panda").ok
    held = np.tile(np.array(limits.lower), (20, 1))
    assert judge_commands(held, "panda").ok
    start = np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])
    steps = np.arange(1, 31, dtype=float) * DT
    for quantity, jerk in (("acceleration", 0.5), ("jerk", 1.5)):
        # a cubic downwards on joint 2: its jerk at that share of the limit; at half of it the
        # acceleration grows past its limit first, at 1.5 times the jerk breaks it at once
        q = np.tile(start, (40, 1))
        q[10:, 1] -= jerk * limits.jerk[1] * steps**3 / 6.0
        verdict = judge_commands(q, "panda")
        assert (verdict.ok, verdict.quantity, verdict.joint) == (False, quantity, 2)
        assert verdict.value < 0 and verdict.bound < 0
    fr3 = FCI_LIMITS["fr3"]
    beyond = np.array(fr3.upper) + 0.01
    lowest, highest = fr3.velocity_bounds(beyond[None])
    np.testing.assert_array_equal(highest[0], 0.0)
    below = np.array(fr3.lower) - 0.01
    lowest, highest = fr3.velocity_bounds(below[None])
    np.testing.assert_array_equal(lowest[0], 0.0)
    near = np.array(fr3.lower) + 0.05
    lowest, _ = fr3.velocity_bounds(near[None])
    expected = -(np.sqrt(2 * np.array(fr3.deceleration) * 0.05) - np.array(fr3.velocity_offset))
    expected = np.minimum(
        0.0, np.maximum(-np.array(fr3.velocity), np.minimum(0.0, expected)) + 1e-3
    )
    np.testing.assert_allclose(lowest[0], expected, rtol=1e-12)
    assert lowest[0, 0] == pytest.approx(-(math.sqrt(2 * 6.0 * 0.05) - 0.3) + 1e-3, rel=1e-12)


def test_verify_says_how_long_a_motion_is_and_refuses_other_rates(tmp_path, capsys):
    """The printed duration and rate, one line for one file, and the 1 kHz check: a file 2 kHz
    apart, one with a single 2 ms gap and one 1.5 µs a step off 1 ms are each refused."""
    from bidmp.cli import main

    names = [f"panda_joint{i}" for i in range(1, 8)]
    start = np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])

    def write(path, t):
        s = np.linspace(0.0, 1.0, len(t))[:, None]
        q = start + 0.05 * (10 * s**3 - 15 * s**4 + 6 * s**5)  # a small rest-to-rest move
        np.savetxt(path, np.column_stack([t, q]), delimiter=",", header="t," + ",".join(names),
                   comments="", fmt="%.17g")  # fmt: skip
        return str(path)

    good = write(tmp_path / "good.csv", np.arange(2500) * 1e-3)
    assert main(["verify", good, "--robot", "panda"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and "2500 commands (2.500 s)" in out[0]
    fast = write(tmp_path / "fast.csv", np.arange(200) * 5e-4)
    assert main(["verify", fast, "--robot", "panda"]) == 2
    assert "0.5 ms apart (2000 Hz)" in capsys.readouterr().err
    gap = np.arange(200) * 1e-3
    gap[100:] += 1e-3
    assert main(["verify", write(tmp_path / "gap.csv", gap), "--robot", "panda"]) == 2
    err = capsys.readouterr().err
    # the step that is off, not the median's "1 ms apart (1000 Hz)": that is no reason to refuse
    assert "data rows 100 and 101 are 2 ms apart" in err and "1000 Hz" not in err, err
    off = np.arange(200) * 1.0015e-3
    assert main(["verify", write(tmp_path / "off.csv", off), "--robot", "panda"]) == 2
    capsys.readouterr()


def _command_file(path, t, q, names, first_lines=()) -> str:
    with open(path, "w") as handle:
        handle.writelines(f"{line}\n" for line in first_lines)
        handle.write("t," + ",".join(names) + "\n")
        for time, row in zip(t, q):
            handle.write(",".join(repr(float(v)) for v in [time, *row]) + "\n")
    return str(path)


def test_verify_refuses_a_length_unit_a_joint_named_twice_and_a_repeated_stamp_truly(
    tmp_path, capsys
):
    """What a joint command file must be, each refusal one line (exit 2) that is true: a length
    unit on joints ('# units: m' is no angle), a joint named twice in the header (which column is
    its command?), a stamp repeated (named, with its data row, not "1 ms apart (1000 Hz)"); and a
    stream that holds still is valid (zero velocity is within every limit): accepted, exit 0."""
    from bidmp.cli import main

    names = [f"fr3_joint{i}" for i in range(1, 8)]
    t = np.arange(800) * 1e-3
    s = np.linspace(0.0, 1.0, 800)[:, None]
    start = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.9, 0.8])
    q = start + 0.05 * (10 * s**3 - 15 * s**4 + 6 * s**5)

    def verify(path):
        capsys.readouterr()
        status = main(["verify", path, "--robot", "fr3"])
        out, err = capsys.readouterr()
        return status, out.strip().splitlines(), err.strip().splitlines()

    assert verify(_command_file(tmp_path / "ok.csv", t, q, names, ["# units: rad"]))[0] == 0
    for unit in ("m", "mm", "cm"):
        status, _, err = verify(
            _command_file(tmp_path / f"{unit}.csv", t, q, names, [f"# units: {unit}"])
        )
        assert status == 2 and len(err) == 1 and f"'# units: {unit}', a length" in err[0], err
    status, _, err = verify(_command_file(tmp_path / "furlong.csv", t, q, names, ["# units: ft"]))
    assert status == 2 and len(err) == 1 and "units must be one of" in err[0], err
    # an eighth column named as the first: read as the first's before, its values dropped
    twice = np.column_stack([q, q[:, 0] + 0.3])
    status, _, err = verify(_command_file(tmp_path / "twice.csv", t, twice, [*names, names[0]]))
    assert status == 2 and len(err) == 1 and "'fr3_joint1' 2 times" in err[0], err
    with pytest.raises(ValueError, match="named 2 times"):
        match_joint_names([*names, names[2]], "fr3")
    still = np.tile(start, (800, 1))
    status, out, _ = verify(_command_file(tmp_path / "still.csv", t, still, names))
    assert status == 0 and out[0].startswith("accepted:") and "800 commands" in out[0], out
    repeated = t.copy()
    repeated[400] = repeated[399]  # the logger wrote one stamp twice, the rest on the 1 ms grid
    status, _, err = verify(_command_file(tmp_path / "repeated.csv", repeated, q, names))
    assert status == 2 and len(err) == 1, err
    assert "data row 401 repeats the stamp 0.399 s" in err[0] and "1000 Hz" not in err[0], err


def test_a_stream_still_moving_at_its_end_is_rejected_after_its_last_command():
    """The robot holds a finished motion's last command: joint 2 brought smoothly (well within
    every limit) to v rad/s and the stream stopping there jumps to rest in one cycle, an
    acceleration of -v / dt (closed form) at the first sample after the last."""
    v, n = 0.02, 600  # 20 rad/s² at the end: over the FR3's 10 and the Panda's 7.5
    u = np.clip(np.arange(n) * DT / 0.3, 0.0, 1.0)
    speed = v * u**3 * (10 - 15 * u + 6 * u**2)  # a smooth rise from rest to v over 0.3 s
    q = np.repeat(np.array([[0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785]]), n, axis=0)
    q[:, 1] += np.concatenate([[0.0], np.cumsum(speed[1:]) * DT])
    for robot in ("fr3", "panda"):
        verdict = judge_commands(q, robot)
        assert not verdict.ok and verdict.after_end and verdict.sample == n
        assert verdict.quantity == "acceleration" and verdict.joint == 2
        assert abs(verdict.value + v / DT) < 1e-6 * v / DT
        assert "after the last command" in verdict.reason()
        assert (
            judge_commands(q[:250], robot).after_end is False
            or not judge_commands(q[:250], robot).ok
        )


def test_the_contract_asks_a_franka_arms_own_fci_beside_its_limits():
    """An FR3 joint 1 moving at 2 rad/s (within the published 2.62) towards the end of its range:
    within the contract's constant limits, but past the FCI's position-based velocity limit
    there, -0.30 + sqrt(2 · 6 · (2.7501 - q)) (closed form): the contract now says so. The same
    stream on an arm without an FCI table passes."""
    from bidmp.sim.robots import FR3, JointLimits
    from bidmp.tasks.contract import Contract

    n = 2000
    t = np.arange(n) * DT
    q = np.repeat(np.array([[2.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785]]), n, axis=0)
    # a smooth rise to 2 rad/s over 0.5 s, then steady: reaches within 0.1 rad of the end
    speed = 2.0 * np.clip(t / 0.5, 0, 1) ** 2 * (3 - 2 * np.clip(t / 0.5, 0, 1))
    q[:, 0] = 2.0 + np.cumsum(speed) * DT
    q = q[q[:, 0] < 2.74]
    bound = -0.30 + np.sqrt(2 * 6.0 * (2.7501 - q[:, 0]))
    assert np.any(np.diff(q[:, 0]) / DT > bound[1:] + 1e-3)  # the oracle: the FCI's bound passed
    contract = Contract(1.75, 25.0, None, "mm", limits=FR3)
    path = np.zeros((len(q), 3))
    verdict = contract.judge(path, np.zeros(3), commands=q)
    assert verdict.limits.reflex.startswith("joint_motion_generator_velocity_limits_violation")
    assert not verdict.within_limits and "controller would stop the motion" in verdict.reason()
    plain = JointLimits(FR3.lower, FR3.upper, FR3.velocity, FR3.acceleration, FR3.jerk)
    peaks = Contract(1.75, 25.0, None, "mm", limits=plain).judge(path, np.zeros(3), commands=q)
    assert peaks.limits.reflex == "" and peaks.limits.velocity < 1.0


def test_the_contract_asks_the_arms_judge_only_at_its_1_khz_and_only_if_it_has_one():
    """Commands 2 ms apart are not what the FCI takes (its tables are per 1 ms): not asked.
    Limits without a judge of their own (any object with velocity, acceleration, jerk): judged
    by those alone."""
    from types import SimpleNamespace

    from bidmp.sim.robots import FR3
    from bidmp.tasks.contract import Contract

    q = np.repeat(np.array([[0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785]]), 60, axis=0)
    q[30:, 1] += 2e-5  # 20 rad/s² at 1 kHz: the FR3's FCI stops it
    path = np.zeros((len(q), 3))
    contract = Contract(1.75, 25.0, None, "mm", limits=FR3)
    assert contract.judge(path, np.zeros(3), commands=q).limits.reflex
    assert contract.judge(path, np.zeros(3), commands=q, dt=2e-3).limits.reflex == ""
    plain = SimpleNamespace(velocity=FR3.velocity, acceleration=FR3.acceleration, jerk=FR3.jerk)
    peaks = Contract(1.75, 25.0, None, "mm", limits=plain).judge(path, np.zeros(3), commands=q)
    assert peaks.limits.reflex == "" and peaks.limits.acceleration > 1.0
