"""Hostile robot files refused at the door, by ``robot_model`` and ``bidmp scenario check``, in one
line that says what is wrong and where: before, a loop, a duplicate link or a missing parent reached
PyBullet (whose error names none of them), NaN or 1e308 joint origins gave NaN kinematics (a
simulation still running after 180 s), and a mesh linked to a system file was followed. Each file is
the TM5-like arm of tests/data with one defect planted."""

from __future__ import annotations

import json
import re
import shutil
import sys
from pathlib import Path

import pytest

from bidmp import set_limits
from bidmp.cli import main
from bidmp.sim import robot_model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tasks"))
from test_user_cells import urdf_limits  # noqa: E402

ARM = Path(__file__).resolve().parents[1] / "data" / "tm5_like" / "tm5_like.urdf"


def _spec(urdf: str) -> dict:
    return {"urdf": urdf, "flange": "flange", "limits": urdf_limits([170.0] * 6, [170.0] * 6)}


def _planted(text: str, defect: str) -> str:
    if defect == "duplicate link":
        return text.replace('<link name="link3">', '<link name="link2">', 1)
    if defect == "missing parent":
        return text.replace('<parent link="link2"/>', '<parent link="elbow"/>', 1)
    if defect == "loop":  # base_link becomes the child of the last joint: no root, a loop
        last = text.rindex('<child link="')
        end = text.index('"/>', last)
        return text[:last] + '<child link="base_link' + text[end:]
    if defect == "nan origin":
        return text.replace('<origin xyz="0.329 0 0.0"', '<origin xyz="nan 0 0.0"', 1)
    if defect == "huge origin":
        return text.replace('<origin xyz="0.329 0 0.0"', '<origin xyz="1e308 0 0.0"', 1)
    if defect == "mesh outside":
        return text.replace(
            '<cylinder radius="0.06" length="0.145200"/>', '<mesh filename="../../etc/passwd"/>', 1
        )
    raise AssertionError(defect)


WORDS = {
    "duplicate link": "two links are named 'link2'",
    "missing parent": "names parent link 'elbow', which is not a <link>",
    "loop": "the joints make a loop",
    "nan origin": "xyz 'nan 0 0.0' must be 3 finite numbers",
    "huge origin": "xyz '1e308 0 0.0' must be 3 finite numbers",
    "mesh outside": "lies outside the URDF's folder",
}


@pytest.mark.parametrize("defect", sorted(WORDS))
def test_a_hostile_urdf_is_refused_by_name(tmp_path, defect, capsys):
    (tmp_path / "arm.urdf").write_text(_planted(ARM.read_text(), defect))
    with pytest.raises(ValueError, match=re.escape(WORDS[defect])):
        robot_model(_spec("arm.urdf"), tmp_path)
    # the same through a scenario file and the command a user runs first
    scenario = json.loads(
        (Path(__file__).resolve().parents[1] / "data" / "two_posts.json").read_text()
    )
    scenario["robot"] = {**_spec("arm.urdf"), "base": [50, -450, 0]}
    (tmp_path / "cell.json").write_text(json.dumps(scenario))
    code = main(["scenario", "check", str(tmp_path / "cell.json")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and WORDS[defect] in err[0], err


def test_the_arm_as_shipped_passes_and_a_mesh_over_the_size_limit_does_not(tmp_path):
    shutil.copy(ARM, tmp_path / "arm.urdf")
    assert robot_model(_spec("arm.urdf"), tmp_path).flange == "flange"
    (tmp_path / "big.stl").write_bytes(bytes(64 * 1024))
    text = ARM.read_text().replace(
        '<cylinder radius="0.06" length="0.145200"/>', '<mesh filename="big.stl"/>', 1
    )
    (tmp_path / "arm.urdf").write_text(text)
    assert robot_model(_spec("arm.urdf"), tmp_path).flange == "flange"  # within the limit
    # over the URDF's 5.5 kB, under the mesh's 64 kB; restored on leaving
    with set_limits(max_file_bytes=16 * 1024), pytest.raises(ValueError, match="size of mesh"):
        robot_model(_spec("arm.urdf"), tmp_path)
