"""A scenario's demonstration file read with bidmp fit's reading options: a logger's CSV (stamps
in milliseconds, decimal commas, roll/pitch/yaw in degrees) given its ``"columns"`` and
``"units"`` beside ``"file"`` reads the motion ``bidmp fit --columns ... --units ...`` reads,
checked against a reading of the file written here (SciPy's Euler angles, the numbers parsed by
hand) and against the model bidmp fit learns from it; the options are checked like every key."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.cli import main
from bidmp.demonstrations.preparation import prepare, prepare_poses
from bidmp.io import load_model
from bidmp.tasks import scenarios

COLUMNS = "t=Time,time=ms,x=X,y=Y,z=Z,e1=Roll,e2=Pitch,e3=Yaw,euler=xyz,angles=deg"


def _logger_file(path, generated: np.ndarray, seed: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """The pose motion ``generated`` (mm, quaternions) over 3 s as a logger writes it: 1 s at rest before
    and after, 0.02 mm of noise, stamps in ms at 250 Hz from a shifted start, x, y, z in mm and
    roll, pitch, yaw in degrees (extrinsic xyz), ';' separated with decimal commas, rounded to
    what the logger prints. Returns (stamps s, poses) as the file holds them."""
    rest = 250
    # at a hand's pace: the 200 samples spread over 3 s (neighbouring quaternions interpolated)
    where = np.linspace(0.0, len(generated) - 1.0, 750)
    generated = np.column_stack(
        [np.interp(where, np.arange(len(generated)), column) for column in generated.T]
    )
    generated[:, 3:] /= np.linalg.norm(generated[:, 3:], axis=1, keepdims=True)
    poses = np.vstack(
        [np.repeat(generated[:1], rest, 0), generated, np.repeat(generated[-1:], rest, 0)]
    )
    rng = np.random.default_rng(seed)
    positions = np.round(poses[:, :3] + rng.normal(0.0, 0.02, (len(poses), 3)), 4)
    angles = np.round(Rotation.from_quat(poses[:, 3:]).as_euler("xyz", degrees=True), 5)
    ms = 12_345 + 4 * np.arange(len(poses))
    with open(path, "w") as handle:
        handle.write("Time;X;Y;Z;Roll;Pitch;Yaw\n")
        for stamp, row in zip(ms, np.hstack([positions, angles])):
            handle.write(";".join([str(stamp), *(f"{v:.5f}".replace(".", ",") for v in row)]))
            handle.write("\n")
    quaternions = Rotation.from_euler("xyz", angles, degrees=True).as_quat()
    return ms / 1e3, np.hstack([positions, quaternions])


def _tilted(tmp_path, demonstration: dict):
    spec = json.loads(scenarios.builtin_text("nut-unscrewing-tilted"))
    spec["demonstration"] = demonstration
    (tmp_path / "cell.json").write_text(json.dumps(spec))
    return tmp_path / "cell.json"


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Degrees between unit quaternions (rows), whatever their signs."""
    return np.degrees((Rotation.from_quat(a) * Rotation.from_quat(b).inv()).magnitude())


def test_a_loggers_recording_reads_in_a_scenario_as_bidmp_fit_reads_it(tmp_path):
    generated = scenarios.load("nut-unscrewing-tilted").demonstration
    t, poses = _logger_file(tmp_path / "log.csv", generated)
    demonstration = {"file": "log.csv", "columns": COLUMNS, "units": "mm"}
    scenario = scenarios.load(str(_tilted(tmp_path, demonstration)))
    read = scenario.demonstration
    # an independent reading: the numbers parsed here, prepared as documented
    expected, _, _ = prepare_poses(poses, t)
    assert read.shape == expected.shape
    np.testing.assert_allclose(read[:, :3], expected[:, :3], rtol=0, atol=1e-9)
    assert np.max(_angle(read[:, 3:], expected[:, 3:])) < 1e-6
    # the motion it holds is the one written (the 6 Hz filter and the trim aside)
    np.testing.assert_allclose(read[0, :3], generated[0, :3], atol=1.0)
    np.testing.assert_allclose(read[-1, :3], generated[-1, :3], atol=1.0)
    assert _angle(read[-1:, 3:], generated[-1:, 3:])[0] < 0.5
    # bidmp fit with the same options learns from the same motion: its start, goal and duration
    model = tmp_path / "fit.npz"
    args = ["fit", str(tmp_path / "log.csv"), "--columns", COLUMNS, "--units", "mm", "-o"]
    assert main([*args, str(model)]) == 0
    fitted = load_model(model)
    np.testing.assert_allclose(fitted.start_[:3], read[0, :3], rtol=0, atol=1e-9)
    np.testing.assert_allclose(fitted.goal_[:3], read[-1, :3], rtol=0, atol=1e-9)
    assert _angle(fitted.goal_[None, 3:], read[-1:, 3:])[0] < 1e-6
    assert scenario.pace is not None and scenario.pace > 0


def test_a_file_in_another_unit_is_converted_and_contradictions_are_refused(tmp_path):
    """Positions in metres (declared in the file, or by "units"): converted to the scenario's
    millimetres as bidmp fit --units converts them; a "units" the file contradicts is refused."""
    nut = json.loads(scenarios.builtin_text("nut-unscrewing"))
    s = np.linspace(0.0, 1.0, 400)[:, None]
    path_mm = np.array([-80.0, -120.0, 200.0]) + (10 * s**3 - 15 * s**4 + 6 * s**5) * np.array(
        [80.0, 120.0, -200.0]
    )
    t = np.arange(400) * 0.005
    rows = "\n".join(",".join(repr(float(v)) for v in [a, *p]) for a, p in zip(t, path_mm / 1e3))
    (tmp_path / "m.csv").write_text(f"# units: m\nt,x,y,z\n{rows}\n")
    (tmp_path / "plain.csv").write_text(f"t,x,y,z\n{rows}\n")
    expected = prepare(path_mm, t)[0].y
    for file, extra in (("m.csv", {}), ("plain.csv", {"units": "m"}), ("m.csv", {"units": "m"})):
        nut["demonstration"] = {"file": file, **extra}
        (tmp_path / "s.json").write_text(json.dumps(nut))
        read = scenarios.load(str(tmp_path / "s.json")).demonstration
        np.testing.assert_allclose(read, expected, rtol=0, atol=1e-9)
    nut["demonstration"] = {"file": "m.csv", "units": "mm"}
    (tmp_path / "s.json").write_text(json.dumps(nut))
    with pytest.raises(scenarios.ScenarioError, match="is in m .* but units says mm"):
        scenarios.load(str(tmp_path / "s.json"))


@pytest.mark.parametrize(
    ("demonstration", "match"),
    [
        ({"file": "log.csv", "colums": "t=Time"}, "demonstration.colums: unknown key"),
        (
            {"file": "log.csv", "columns": "t=Time,w=W"},
            "demonstration.columns: columns: unknown role",
        ),
        ({"file": "log.csv", "columns": 3}, "demonstration.columns: expected a column mapping"),
        ({"file": "log.csv", "units": "inch"}, "demonstration.units: expected the file's length"),
        ({"file": "log.csv", "units": "rad"}, "demonstration.units: expected the file's length"),
        (
            {"points": [[0, 0, 0]] * 12, "columns": "t=Time"},
            'demonstration.columns: unknown key (only a "file" demonstration',
        ),
        ({"file": "log.csv", "points": []}, "demonstration: expected exactly one of"),
        # the logger's file without its conventions: refused naming the declaration it needs
        ({"file": "log.csv"}, "demonstration.file:"),
        (
            {"file": "log.csv", "columns": COLUMNS.replace(",angles=deg", "")},
            "demonstration.file:",
        ),
    ],
)
def test_a_file_demonstrations_options_are_checked_like_every_key(tmp_path, demonstration, match):
    _logger_file(tmp_path / "log.csv", scenarios.load("nut-unscrewing-tilted").demonstration)
    with pytest.raises(scenarios.ScenarioError, match=match.replace("(", r"\(")) as raised:
        scenarios.load(str(_tilted(tmp_path, demonstration)))
    assert len(str(raised.value).splitlines()) == 1
