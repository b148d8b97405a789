"""The README tells the truth: its result tables are the committed outputs of the commands that
make them, and every Python block runs on its own."""

import importlib.util
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def readme_tool():
    spec = importlib.util.spec_from_file_location("readme_tool", ROOT / "tools" / "readme.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_tables_equal_the_committed_command_outputs():
    blocks = readme_tool().blocks(README)
    assert {path for path, _ in blocks} == {
        "docs/results/table4.md",
        "docs/results/tasks.md",
        "docs/results/table5.md",
        "docs/results/figures.md",
        "docs/results/sim.md",
        "docs/results/lasa.md",
        "docs/results/robot.md",
        "docs/results/avoidance.md",
        "docs/results/job.md",
        "docs/results/job_cells.md",
        "docs/results/repair_order.md",
        "docs/results/user_cells.md",
    }
    for path, body in blocks:
        committed = (ROOT / path).read_text(encoding="utf-8")
        assert body.strip() == committed.strip(), f"README block {path} is stale: run 'make readme'"


PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", README, re.DOTALL)


@pytest.mark.parametrize("index", range(len(PYTHON_BLOCKS)))
def test_every_python_block_runs_alone(index, tmp_path):
    result = subprocess.run(
        [sys.executable, "-c", PYTHON_BLOCKS[index]],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr[-2000:]


def test_the_readme_limits_table_states_the_defaults_in_force():
    import dataclasses

    import bidmp

    rows = dict(re.findall(r"^\| `(max_\w+|min_\w+)` \| ([^|]+) \|", README, re.MULTILINE))
    defaults = dataclasses.asdict(bidmp.Limits())
    assert set(rows) == set(defaults), "document every limit in the README table"
    for name, value in defaults.items():
        assert float(rows[name]) == float(value), name


def test_the_robot_protocol_table_is_what_its_tool_measures(tmp_path):
    """docs/results/robot.md (the README's robot-protocol numbers) against a fresh run of
    tools/robot_protocol.py (about 6 s)."""
    out = tmp_path / "robot.md"
    subprocess.run(
        [sys.executable, str(ROOT / "tools" / "robot_protocol.py"), "--out", str(out)],
        check=True,
        capture_output=True,
        timeout=120,
    )
    assert out.read_text() == (ROOT / "docs" / "results" / "robot.md").read_text()


def test_the_readme_cites_only_files_in_the_repository():
    """The README once cited SPEC.md and ARCHITECTURE.md, which live outside it. Every
    repository path it names (docs/, tools/, benchmarks/, tests/, src/) exists."""
    for outside in ("SPEC.md", "ARCHITECTURE.md", "../shared"):
        assert outside not in README, outside
    for name in re.findall(r"\b((?:docs|tools|benchmarks|tests|src)/[\w./-]*\w)", README):
        assert (ROOT / name).exists(), name


def test_the_own_robot_commands_run_as_written(tmp_path, monkeypatch, capsys):
    """the section "Your own robot and data" — its Python block, then every command of
    its marked block in order, in one folder (each may use what the ones before it wrote)."""
    import shlex
    import shutil

    pytest.importorskip("pybullet")
    pytest.importorskip("rosbags")
    pytest.importorskip("plotly")
    from bidmp.cli import main

    section = README.split("## Your own robot and data", 1)[1].split("\n## ", 1)[0]
    python = re.search(r"```python\n(.*?)```", section, re.DOTALL).group(1)
    commands = re.search(r"<!-- own-robot-commands -->\n```sh\n(.*?)```", section, re.DOTALL).group(
        1
    )
    shutil.copy(
        ROOT / "src" / "bidmp" / "data" / "recordings" / "operator1_nut3.csv",
        tmp_path / "recording.csv",
    )
    monkeypatch.chdir(tmp_path)
    exec(compile(python, "README", "exec"), {})
    lines = [line for line in commands.splitlines() if line.startswith("bidmp ")]
    assert len(lines) >= 8
    for line in lines:
        assert main(shlex.split(line)[1:]) == 0, (line, capsys.readouterr().err[-500:])
    assert (tmp_path / "viewed" / "view.html").is_file() and (tmp_path / "joints.bag").is_file()
