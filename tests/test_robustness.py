"""no input crashes bidmp. One test (or a few) per defect class 1-10 of the fuzzing
campaign; each failed before the fix. The generated campaign itself is tests/test_fuzz.py."""

import contextlib
import io
import json
import os
import signal
import stat
import subprocess
import sys
import textwrap
import tracemalloc
import warnings
import zipfile

import numpy as np
import pytest
from conftest import curved_demo

import bidmp
from bidmp.cli import main
from bidmp.io import (
    ModelFileError,
    load_model,
    load_trajectory,
    save_model,
    save_trajectory,
)

PYTHON = sys.executable
from bidmp.demonstrations import recording_path  # noqa: E402  (the bundled copies of shared/data/recordings)


def cli(argv):
    """Run the CLI in this process; return (exit code, stdout, stderr). (How long the commands
    take is benchmarks/bench_robustness.py's: no clock in the tests.)"""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def assert_one_line_error(argv, match=None):
    code, _, err = cli(argv)
    assert code == 2, (argv, code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err and "internal error" not in err
    if match is not None:
        assert match in err, err
    return err


@pytest.fixture
def model_file(tmp_path):
    return save_model(bidmp.DMP(protocol="paper").fit(curved_demo(200, 3)), tmp_path / "model.npz")


def rewrite_archive(path, change):
    """Rewrite the members of an .npz: ``change(members: dict name -> bytes)``."""
    with zipfile.ZipFile(path) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    change(members)
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)


def npy_bytes(array):
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    return buffer.getvalue()


def npy_header_only(shape, dtype="<f8"):
    """An .npy header that declares ``shape`` and no data at all."""
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buffer, {"descr": dtype, "fortran_order": False, "shape": shape}
    )
    return buffer.getvalue()


def set_meta_text(path, change):
    """Rewrite the raw JSON text of a model's metadata: ``change(text) -> text``."""

    def edit(members):
        text = np.load(io.BytesIO(members["__bidmp__.npy"])).tobytes().decode()
        members["__bidmp__.npy"] = npy_bytes(np.frombuffer(change(text).encode(), np.uint8))

    rewrite_archive(path, edit)


def set_meta(path, change):
    def edit(members):
        meta = json.loads(np.load(io.BytesIO(members["__bidmp__.npy"])).tobytes())
        change(meta)
        members["__bidmp__.npy"] = npy_bytes(np.frombuffer(json.dumps(meta).encode(), np.uint8))

    rewrite_archive(path, edit)


# --- 1. CLI: huge or malformed files and sizes are one line, exit 2, within seconds --------------
def test_csv_field_over_the_csv_module_limit(tmp_path):
    path = tmp_path / "long.csv"
    path.write_text("x,y\n0,0\n" + "a" * 200_000 + ",1\n2,2\n")
    assert_one_line_error(["fit", path, "-o", tmp_path / "m.npz"], "not a CSV row")
    path.write_text("x,y\n0,0\n" + "1" * 200_000 + ",1\n2,2\n")  # a number beyond float64
    assert_one_line_error(["fit", path, "-o", tmp_path / "m.npz"], "contains inf")


def test_npz_renamed_npy_and_raw_members(tmp_path, model_file):
    renamed = tmp_path / "renamed.npy"
    renamed.write_bytes(model_file.read_bytes())
    assert_one_line_error(["segment", renamed], "is an .npz archive")
    rewrite_archive(model_file, lambda m: m.update({"weights_.npy": b"\x00" * 64}))
    assert_one_line_error(["rollout", model_file, "-o", tmp_path / "r.csv"], "weights_")


def test_deeply_nested_json_in_model_metadata_and_scenarios(tmp_path, model_file):
    set_meta_text(
        model_file,
        lambda text: text.replace(
            '"state": {', '"state": {"deep": ' + "[" * 5000 + "]" * 5000 + ", ", 1
        ),
    )
    assert_one_line_error(["rollout", model_file, "-o", tmp_path / "r.csv"], "max_json_depth")
    scenario = tmp_path / "deep.json"
    scenario.write_text('{"name": ' + "[" * 100_000 + "]" * 100_000 + "}")
    assert_one_line_error(["scenario", "check", scenario], "max_json_depth")
    assert_one_line_error(
        ["demo", "--scenario", scenario, "--out", tmp_path / "o"], "max_json_depth"
    )


def test_declared_sizes_are_refused_before_allocating(tmp_path, model_file):
    huge = tmp_path / "huge.npy"
    huge.write_bytes(npy_header_only((10**12, 2)))
    assert_one_line_error(["segment", huge], "max_samples")
    wide = tmp_path / "wide.npy"
    wide.write_bytes(npy_header_only((10**5, 10**5)))
    assert_one_line_error(["fit", wide, "-o", tmp_path / "m.npz"], "max_")
    rewrite_archive(model_file, lambda m: m.update({"weights_.npy": npy_header_only((10**9, 3))}))
    assert_one_line_error(["rollout", model_file, "-o", tmp_path / "r.csv"], "max_array_bytes")


def test_huge_n_steps_and_n_kernels(tmp_path, model_file):
    demo = save_trajectory(curved_demo(200, 3), tmp_path / "demo.csv")
    for n_steps in (10**8, 10**12, 2**63):
        assert_one_line_error(
            ["rollout", model_file, "-o", tmp_path / "r.csv", "--n-steps", n_steps], "max_steps"
        )
    assert_one_line_error(
        ["fit", demo, "-o", tmp_path / "m.npz", "--n-kernels", 10**9, "--no-time"], "max_kernels"
    )


def test_unsupported_compression_and_encrypted_members(tmp_path, model_file):
    bz2 = tmp_path / "bz2.npz"
    with (
        zipfile.ZipFile(model_file) as source,
        zipfile.ZipFile(bz2, "w", compression=zipfile.ZIP_BZIP2) as target,
    ):
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
    assert_one_line_error(["rollout", bz2, "-o", tmp_path / "r.csv"], "unsupported compression")
    # Set the "encrypted" bit in the local and central headers of every member.
    data = bytearray(model_file.read_bytes())
    for signature, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        position = data.find(signature)
        while position >= 0:
            data[position + offset] |= 0x1
            position = data.find(signature, position + 4)
    encrypted = tmp_path / "encrypted.npz"
    encrypted.write_bytes(bytes(data))
    assert_one_line_error(["rollout", encrypted, "-o", tmp_path / "r.csv"], "encrypted")


def test_segment_on_a_million_row_recording_takes_seconds(tmp_path):
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 1.0, 1_000_000)
    y = np.column_stack([np.cos(3 * t), np.sin(5 * t), t]) * 100 + rng.normal(
        scale=0.01, size=(t.size, 3)
    )
    path = tmp_path / "long.npy"
    np.save(path, y)
    code, out, err = cli(["segment", path])
    assert code == 0, err
    assert "1000000 samples" in out
    csv_path = tmp_path / "long.csv"
    np.savetxt(
        csv_path,
        np.column_stack([1.7e9 + t * 4000.0, y]),
        delimiter=",",
        header="t,x,y,z",
        comments="",
        fmt="%.6f",
    )
    code, out, err = cli(["segment", csv_path, "--raw"])
    assert code == 0 and "1000000 samples" in out, err
    code, out, err = cli(["segment", csv_path])  # timed input is prepared, as by fit
    assert code == 0 and "prepared: kept" in out, err
    points = bidmp.segment(y).points  # its time: benchmarks/bench_robustness.py
    assert np.all((points > 0) & (points < y.shape[0]))


def test_persistence_pruning_matches_the_literal_quadratic_rule():
    from bidmp.extension.segmentation import _prune_persistence, _prune_persistence_plain

    rng = np.random.default_rng(3)
    for trial in range(200):
        n = int(rng.integers(0, 60))
        kappa = np.round(rng.random(200), 1 if trial % 2 else 6)  # coarse values force ties
        indices = np.sort(rng.choice(200, size=n, replace=False))
        types = np.where(np.arange(n) % 2 == 0, 1, -1)
        epsilon = float(rng.uniform(0.0, 0.6))
        fast = _prune_persistence(indices, types, kappa, epsilon)
        plain = _prune_persistence_plain(indices, types, kappa, epsilon)
        np.testing.assert_array_equal(fast[0], plain[0])
        np.testing.assert_array_equal(fast[1], plain[1])


def test_segmentation_of_long_demonstrations_matches_short_ones():
    """Analysing 4096 arc-length samples instead of all of them keeps the segmentation points."""
    short = curved_demo(2000, 3, seed=4)
    long = np.vstack(
        [np.interp(np.linspace(0, 1999, 20_000), np.arange(2000), c) for c in short.T]
    ).T
    s_short = bidmp.segment(short).points / 1999
    s_long = bidmp.segment(long).points / 19_999
    assert len(s_short) == len(s_long)
    np.testing.assert_allclose(s_short, s_long, atol=0.01)


# --- 2. huge but finite inputs: refused up front, no warnings, no NaN ------------------------------
@pytest.mark.parametrize("scale", [1e300, 1e200, 1e12])
def test_huge_inputs_are_refused_without_warnings(scale, tmp_path):
    demo = curved_demo(100, 3) * scale
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="max_abs_value"):
            bidmp.DMP(protocol="paper").fit(demo)
        with pytest.raises(ValueError, match="max_abs_value"):
            bidmp.frechet_distance(demo, demo[::-1])
        with pytest.raises(ValueError, match="max_abs_value"):
            bidmp.extend_demonstration(curved_demo(100, 3), [scale, 0, 0])
        dmp = bidmp.DMP(protocol="paper").fit(curved_demo(100, 3))
        with pytest.raises(ValueError, match="max_abs_value"):
            dmp.rollout(goal=[scale, 0.0, 0.0])
    path = tmp_path / "huge.csv"
    save_trajectory(curved_demo(100, 3), path)
    lines = path.read_text().splitlines()
    lines[5] = f"{scale:g},0,0"
    path.write_text("\n".join(lines) + "\n")
    assert_one_line_error(["fit", path, "-o", tmp_path / "m.npz"], "max_abs_value")


def test_tiny_motions_are_refused_not_divided_by():
    with pytest.raises(ValueError, match="barely moves"):
        bidmp.DMP(protocol="paper").fit(curved_demo(100, 3) * 1e-300)
    with pytest.raises(ValueError, match="barely moves"):
        bidmp.segment(1e6 + curved_demo(100, 3) * 1e-8)


def test_limits_can_be_raised_in_the_library_and_are_restored():
    demo = curved_demo(100, 3) * 1e10
    with pytest.raises(ValueError, match="max_abs_value"):
        bidmp.DMP(protocol="paper").fit(demo)
    with bidmp.set_limits(max_abs_value=1e12):
        assert bidmp.get_limits().max_abs_value == 1e12
        assert np.all(np.isfinite(bidmp.DMP(protocol="paper").fit(demo).rollout()))
    assert bidmp.get_limits().max_abs_value == 1e9
    with pytest.raises(TypeError, match="unknown limit"):
        bidmp.set_limits(max_bananas=3)
    with pytest.raises(ValueError, match="max_steps must be >= 1"):
        bidmp.set_limits(max_steps=0)


# --- 3. dependency exceptions become ValueError / TypeError naming the argument ----------------
@pytest.mark.parametrize(
    "seed, error",
    [(-1, ValueError), (2**130, ValueError), (1.5, TypeError), ("7", TypeError), (None, TypeError)],
)
def test_bad_seeds_are_named(seed, error):
    with pytest.raises(error, match="seed"):
        bidmp.extend_demonstration(curved_demo(100, 3), [1.0, 1.0, 1.0], seed=seed)


def test_singular_bls_and_oversized_bls_are_value_errors(peak_memory):
    X = np.tile(np.linspace(0, 1, 50)[:, None], (1, 3))
    with pytest.raises(ValueError, match="reg"):
        bidmp.BLS(reg=1e-300, update="exact_ridge").fit(X, X[:, 0])
    data = np.random.default_rng(0).random((20_000, 3))  # allocated before the refusals
    peak = peak_memory()
    with peak:
        for params in (
            {"n_windows": 10**6},
            {"n_enhance": 10**7},
            {"n_windows": 50, "n_mapped": 50, "n_enhance": 2000},
            {"admm_iterations": 10**9},
        ):
            with pytest.raises(ValueError, match="max_hidden_nodes|admm_iterations"):
                bidmp.BLS(**params).fit(X, X[:, 0])
        with pytest.raises(ValueError, match="max_work"):
            bidmp.BLS(n_enhance=2500).fit(data, np.zeros(20_000))
    # refused before the work: the last one's enhancement layer alone would be 400 MB
    assert peak.megabytes < 20.0, peak.megabytes


def test_load_never_leaks_attribute_index_or_recursion_errors(tmp_path, model_file):
    cases = [
        lambda meta: meta.update(state=[]),
        lambda meta: meta["state"].update(params=[1, 2]),
        lambda meta: meta["state"].update(n_steps_="many"),
        lambda meta: meta["state"]["params"].update(n_kernels=10**9),
        lambda meta: meta["state"]["params"].update(bogus=1),
        lambda meta: meta.pop("state"),
    ]
    for index, change in enumerate(cases):
        path = save_model(
            bidmp.DMP(protocol="paper").fit(curved_demo(200, 3)), tmp_path / f"m{index}.npz"
        )
        set_meta(path, change)
        with pytest.raises(ModelFileError):
            load_model(path)


# --- 4. files: modes, messages, lengths, temporaries, pipes -------------------------------------
@pytest.mark.parametrize("umask, expected", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_outputs_honour_the_umask(tmp_path, umask, expected):
    old = os.umask(umask)
    try:
        paths = [
            save_model(bidmp.DMP(protocol="paper").fit(curved_demo(50, 2)), tmp_path / "m.npz"),
            save_trajectory(curved_demo(50, 2), tmp_path / "t.csv"),
            save_trajectory(curved_demo(50, 2), tmp_path / "t.npy"),
        ]
    finally:
        os.umask(old)
    for path in paths:
        assert stat.S_IMODE(path.stat().st_mode) == expected, path


def test_overwriting_keeps_the_files_mode(tmp_path):
    path = save_trajectory(curved_demo(50, 2), tmp_path / "t.csv")
    os.chmod(path, 0o640)
    save_trajectory(curved_demo(60, 2), path)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert load_trajectory(path).shape == (60, 2)


def test_a_csv_given_as_a_model_is_not_answered_with_pickle_advice(tmp_path):
    path = save_trajectory(curved_demo(50, 3), tmp_path / "demo.csv")
    err = assert_one_line_error(
        ["rollout", path, "-o", tmp_path / "r.csv"], "not a bidmp model file"
    )
    assert "pickle" not in err


def test_extend_with_a_demonstration_of_another_length(tmp_path):
    model = save_model(bidmp.DMP(protocol="paper").fit(curved_demo(200, 3)), tmp_path / "m.npz")
    demo = save_trajectory(curved_demo(333, 3), tmp_path / "d.csv")
    code, out, err = cli(
        ["extend", model, demo, "--target", 1.5, 1.5, 1.5, "-o", tmp_path / "e.npz"]
    )
    assert code == 0, err
    assert np.all(np.isfinite(load_model(tmp_path / "e.npz").rollout([1.5, 1.5, 1.5])))


def test_a_writer_killed_mid_write_leaves_nothing_the_next_write_keeps(tmp_path):
    target = tmp_path / "out.npy"
    save_trajectory(curved_demo(50, 2), target)
    script = textwrap.dedent(f"""
        import time
        from bidmp.io import atomic_write
        with atomic_write({str(target)!r}, "wb") as handle:
            handle.write(b"x" * 1_000_000)
            handle.flush()
            print("writing", flush=True)
            time.sleep(60)
    """)
    process = subprocess.Popen([PYTHON, "-c", script], stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "writing"
    temporaries = list(tmp_path.glob(".out.npy.*.bidmp-tmp"))
    assert len(temporaries) == 1  # recognisably named
    process.send_signal(signal.SIGKILL)
    process.wait()
    process.stdout.close()
    assert load_trajectory(target).shape == (50, 2)  # the old file is intact
    # A live writer's temporary (this process's pid) must survive the clean-up.
    live = tmp_path / f".out.npy.{os.getpid()}.abcdef.bidmp-tmp"
    live.write_bytes(b"in progress")
    save_trajectory(curved_demo(70, 2), target)
    assert not temporaries[0].exists() and live.exists()
    assert load_trajectory(target).shape == (70, 2)


def test_a_closed_pipe_ends_quietly():
    process = subprocess.Popen(
        [PYTHON, "-m", "bidmp", "scenario", "show", "nut-unscrewing"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    process.stdout.close()  # like `| head` exiting before bidmp writes
    _, err = process.communicate(timeout=60)
    assert err == b"", err
    assert process.returncode in (0, 141)


# --- 5. model files: every loaded array validated, unneeded members never read -----------------
@pytest.mark.parametrize("member", ["weights_", "centres_", "goal_", "start_", "widths_"])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_dmp_members_are_refused_by_name(tmp_path, model_file, member, bad):
    def poison(members):
        array = np.load(io.BytesIO(members[f"{member}.npy"]))
        array.flat[0] = bad
        members[f"{member}.npy"] = npy_bytes(array)

    rewrite_archive(model_file, poison)
    with pytest.raises(ModelFileError, match=member):
        load_model(model_file)


def test_wrong_shapes_and_dtypes_are_refused_by_name(tmp_path, model_file):
    for member, value in (
        ("weights_", np.ones((7, 3))),
        ("goal_", np.ones(2)),
        ("centres_", np.ones((50, 2))),
        ("start_", np.array(["a", "b", "c"])),
    ):
        path = tmp_path / f"{member}.npz"
        path.write_bytes(model_file.read_bytes())
        rewrite_archive(path, lambda m: m.update({f"{member}.npy": npy_bytes(value)}))
        with pytest.raises(ModelFileError, match=member):
            load_model(path)


@pytest.fixture(scope="module")
def bidmp_model_bytes(tmp_path_factory):
    demo = curved_demo(150, 3)
    model = bidmp.BiDMP(bidmp.DMP(protocol="paper").fit(demo), increments=(5,))
    model.learn(demo + np.linspace(0, 1, 150)[:, None] * [0.3, 0.2, 0.0])
    return save_model(model, tmp_path_factory.mktemp("bidmp") / "b.npz").read_bytes()


@pytest.mark.parametrize(
    "member",
    [
        "block0/enhancement_scales_",
        "skill_goals_",
        "block0/output_weights_",
        "block0/mapping_range_",
        "dmp/weights_",
    ],
)
def test_non_finite_bidmp_members_are_refused_by_name(tmp_path, bidmp_model_bytes, member):
    path = tmp_path / "b.npz"
    path.write_bytes(bidmp_model_bytes)

    def poison(members):
        array = np.load(io.BytesIO(members[f"{member}.npy"]))
        array.flat[-1] = np.nan
        members[f"{member}.npy"] = npy_bytes(array)

    rewrite_archive(path, poison)
    with pytest.raises(ModelFileError, match=member.split("/")[-1]):
        load_model(path)
    assert_one_line_error(["rollout", path, "-o", tmp_path / "r.csv"], member.split("/")[-1])


def test_loading_never_materialises_a_member_it_does_not_need(tmp_path, model_file):
    extra = np.zeros(8 << 20)  # 64 MiB that no DMP asks for
    with zipfile.ZipFile(model_file, "a") as archive:
        archive.writestr("extra.npy", npy_bytes(extra))
    del extra
    tracemalloc.start()
    try:
        model = load_model(model_file)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 16 << 20, f"loading peaked at {peak / 2**20:.0f} MiB"
    assert np.all(np.isfinite(model.rollout()))


# --- 6. unstable settings are refused, naming the bound --------------------------------------
def test_unstable_euler_settings_are_refused(tmp_path):
    demo = save_trajectory(curved_demo(1000, 3), tmp_path / "demo.csv")
    assert_one_line_error(
        [
            "fit",
            demo,
            "-o",
            tmp_path / "m.npz",
            "--alpha",
            5000,
            "--protocol",
            "paper",
            "--no-time",
        ],
        "dt/tau <",
    )
    assert not (tmp_path / "m.npz").exists()
    # The robot protocol integrates exactly: stable at any step, so the same gains run.
    stiff = bidmp.DMP(alpha=5000.0).fit(curved_demo(1000, 3))
    assert np.all(np.isfinite(stiff.rollout())) and np.all(np.isfinite(stiff.trajectory(dt=0.1).y))
    with pytest.raises(ValueError, match="unstable|alpha_phase"):
        bidmp.DMP(protocol="paper", tau=0.001, alpha_phase=0.001, K="pastor").fit(
            curved_demo(1000, 3)
        )
    dmp = bidmp.DMP(protocol="paper").fit(curved_demo(1000, 3))
    dmp.tau = 0.001  # changed after fit: refused at the rollout
    with pytest.raises(ValueError, match="unstable"):
        dmp.rollout()


def test_the_euler_stability_bound_is_the_closed_form_one():
    from bidmp.primitives.integrate import (
        _euler_spectral_radius as euler_spectral_radius,
    )

    # Critically damped (beta = alpha/4): a double root 1 - h alpha / 2, stable iff h alpha < 4.
    for h_alpha in (0.1, 1.0, 2.0, 3.0, 3.99, 4.01, 5.0):
        alpha = 25.0
        radius = euler_spectral_radius(h_alpha / alpha, alpha, alpha / 4)
        assert radius == pytest.approx(abs(1 - h_alpha / 2), abs=1e-6)
    # Rollouts grow exactly where the radius says so.
    demo = curved_demo(100, 2)
    assert np.all(
        np.isfinite(bidmp.DMP(protocol="paper", alpha=390.0).fit(demo).rollout(n_steps=5000))
    )  # h alpha = 3.9
    with pytest.raises(ValueError, match="unstable"):
        bidmp.DMP(protocol="paper", alpha=410.0).fit(demo)  # h alpha = 4.1


BASE_SCENARIO = {
    "name": "t",
    "targets": {"a": [0.0, 0.0, 0.0], "b": [10.0, 0.0, 0.0]},
    "demonstrated": "a",
    "demonstration": {"minimum_jerk": {"via": [[0, 0, 40], [0, 0, 0]], "n_steps": 200}},
}


@pytest.mark.parametrize(
    "change, match",
    [
        (lambda d: d.update(demonstration={"points": [[0, 0, 0], [1, 1, 1]]}), "at least 10"),
        (lambda d: d.update(demonstration={"points": [[1, 1, 1]] * 20}), "identical"),
        (lambda d: d.update(dmp={"alpha_phase": 1000}), "alpha_phase"),
        (lambda d: d.update(dmp={"tau": 1e-9}), "tau"),
        (lambda d: d.update(dmp={"n_kernels": 10**9}), "max_kernels"),
        (lambda d: d["targets"].update(b=[1e12, 0, 0]), "max_abs_value"),
        (lambda d: d.update(bidmp={"n_enhance": 10**8}), "max_hidden_nodes"),
        (lambda d: d.update(extension={"n_samples": 10**9}), "max_roadmap_nodes"),
        (lambda d: d.update(extension={"seed": 3}), "unknown parameter"),
        (lambda d: d.update(seed=2**40), "seed"),
    ],
)
def test_scenario_check_runs_what_demo_runs(tmp_path, change, match):
    data = json.loads(json.dumps(BASE_SCENARIO))
    change(data)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))
    assert_one_line_error(["scenario", "check", path], match)
    assert_one_line_error(["demo", "--scenario", path, "--out", tmp_path / "o"], match)


# --- 7. rollout_many: chunked output instead of one huge block -------------------------------
def test_rollout_many_refuses_a_huge_block_and_says_how_to_chunk(tmp_path, peak_memory):
    dmp = bidmp.DMP(protocol="paper").fit(curved_demo(1000, 2))
    goals = np.zeros((1_000_000, 2))
    with (
        peak_memory() as peak,
        pytest.raises(ValueError, match="14.9 GiB.*open_memmap.*iter_rollouts"),
    ):
        dmp.rollout_many(goals)
    assert peak.megabytes < 20.0, peak.megabytes  # refused before allocating the block
    goals = np.random.default_rng(0).normal(size=(300, 2))
    expected = dmp.rollout_many(goals)
    out = np.lib.format.open_memmap(
        tmp_path / "r.npy", mode="w+", dtype="float64", shape=expected.shape
    )
    assert dmp.rollout_many(goals, out=out) is out
    np.testing.assert_array_equal(np.load(tmp_path / "r.npy"), expected)
    chunks = list(dmp.iter_rollouts(goals, chunk_size=64))
    assert [first for first, _ in chunks] == [0, 64, 128, 192, 256]
    np.testing.assert_array_equal(np.concatenate([block for _, block in chunks]), expected)
    with pytest.raises(ValueError, match="out must be"):
        dmp.rollout_many(goals, out=np.zeros((3, 3)))


# --- 8. scenario files cannot read outside their folder or echo what they read ---------------
def test_scenario_files_stay_inside_the_scenario_folder(tmp_path):
    folder = tmp_path / "scenarios"
    folder.mkdir()
    secret = tmp_path / "secret.csv"
    secret.write_text("x,y,z\nadmin,hunter2hunter2,x\n")
    os.symlink(secret, folder / "link.csv")
    for name in ("../secret.csv", str(secret), "link.csv"):
        data = dict(BASE_SCENARIO, demonstration={"file": name})
        path = folder / "s.json"
        path.write_text(json.dumps(data))
        err = assert_one_line_error(["scenario", "check", path], "outside the scenario's folder")
        assert "admin" not in err and "hunter2" not in err
        # Allowed explicitly, the file is read, and its text is never quoted whole (a column of text
        # in every row is named by its header only).
        err = assert_one_line_error(
            ["scenario", "check", path, "--allow-outside-files"], "holds text, not numbers"
        )
        assert "hunter2hunter2" not in err
    inside = folder / "demo.csv"
    save_trajectory(curved_demo(100, 3), inside)
    (folder / "s.json").write_text(
        json.dumps(dict(BASE_SCENARIO, demonstration={"file": "demo.csv"}))
    )
    code, out, err = cli(["scenario", "check", folder / "s.json"])
    assert code == 0, err


# --- 9. output paths: symlinks, folders, devices ----------------------------------------------
def test_output_paths_symlinks_folders_and_devices(tmp_path):
    demo = save_trajectory(curved_demo(100, 3), tmp_path / "demo.csv")
    real = save_trajectory(curved_demo(20, 3), tmp_path / "real.csv")
    link = tmp_path / "link.csv"
    os.symlink(real, link)
    save_trajectory(curved_demo(30, 3), link)
    assert link.is_symlink() and load_trajectory(real).shape == (30, 3)  # written through
    (tmp_path / "somedir").mkdir()
    assert_one_line_error(["fit", demo, "-o", tmp_path / "somedir", "--no-time"], "is a folder")
    assert not (tmp_path / "somedir.npz").exists()
    assert_one_line_error(["fit", demo, "-o", "/dev/null", "--no-time"], "not a regular file")
    assert not os.path.exists("/dev/null.npz")
    assert_one_line_error(["lasa", "export", "Sshape", "-o", tmp_path / "somedir"], "is a folder")


# --- 10. read-only caches, BOMs, absurd integers, empty method lists ----------------------------
def test_numba_without_a_writable_cache_compiles_in_memory():
    script = textwrap.dedent("""
        import numba.core.caching as caching
        caching.CacheImpl._locator_classes = []  # no cache folder anywhere, as for a read-only install
        import numpy as np
        from bidmp.extension import frechet_distance
        print(frechet_distance(np.zeros((3, 2)), np.ones((4, 2))))
    """)
    result = subprocess.run([PYTHON, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert float(result.stdout) == pytest.approx(np.sqrt(2.0))


def test_utf8_bom_csv_is_read(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_bytes(
        b"\xef\xbb\xbf"
        + b"t,x,y\n"
        + b"".join(f"{i / 100},{i},{i * i / 50}\n".encode() for i in range(20))
    )
    assert load_trajectory(path).shape == (20, 2)


def test_huge_n_steps_in_the_library_and_empty_methods(tmp_path):
    dmp = bidmp.DMP(protocol="paper").fit(curved_demo(100, 2))
    for n_steps in (2**63, 10**12):
        with pytest.raises(ValueError, match="max_steps"):
            dmp.rollout(n_steps=n_steps)
        with pytest.raises(ValueError, match="max_steps"):
            dmp.endpoint_gain(n_steps)
    assert_one_line_error(["demo", "--methods", ",", "--out", tmp_path / "o"], "names no method")


def test_real_recordings_survive_the_whole_cli(tmp_path):
    for name in ("operator1_nut3", "operator2_nut5"):
        recording = recording_path(name)
        code, out, err = cli(["fit", recording, "-o", tmp_path / "m.npz"])
        assert code == 0 and "RMSE" in out, err
        code, out, err = cli(["segment", recording])
        assert code == 0, err


def test_long_noisy_minimum_jerk_is_fast_and_equals_the_direct_filter():
    from scipy.ndimage import gaussian_filter1d

    from bidmp._noise import _low_pass

    noise = np.random.default_rng(1).normal(size=(30_000, 3))
    np.testing.assert_allclose(
        _low_pass(noise, 600.0), gaussian_filter1d(noise, 600.0, axis=0), atol=1e-12
    )
    # its time: benchmarks/bench_robustness.py
    y = bidmp.demonstrations.minimum_jerk([[0, 0, 0], [100, 50, 20]], 1_000_000, noise=1.0)
    assert np.all(np.isfinite(y))
