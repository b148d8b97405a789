"""The documentation tells the truth: the README and the guides (docs/guides/), their result tables
the committed outputs of the commands that make them, every Python block running on its own."""

import importlib.util
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGES = {
    path: path.read_text(encoding="utf-8")
    for path in [ROOT / "README.md", *sorted((ROOT / "docs" / "guides").glob("*.md"))]
}
DOCS = "\n".join(PAGES.values())
README = PAGES[ROOT / "README.md"]
GUIDE = {path.stem: text for path, text in PAGES.items()}


def readme_tool():
    spec = importlib.util.spec_from_file_location("readme_tool", ROOT / "tools" / "readme.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_tables_equal_the_committed_command_outputs():
    blocks = readme_tool().blocks(DOCS)
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
        "docs/results/clfd_capacity.md",
    }
    for path, body in blocks:
        committed = (ROOT / path).read_text(encoding="utf-8")
        assert body.strip() == committed.strip(), f"README block {path} is stale: run 'make readme'"


PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", DOCS, re.DOTALL)


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

    rows = dict(re.findall(r"^\| `(max_\w+|min_\w+)` \| ([^|]+) \|", DOCS, re.MULTILINE))
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
    for page, text in PAGES.items():
        for outside in ("SPEC.md", "ARCHITECTURE.md", "../shared"):
            assert outside not in text, (page.name, outside)
        for name in re.findall(
            r"(?<![\w./])((?:docs|tools|benchmarks|tests|src)/[\w./-]*\w)", text
        ):
            assert (ROOT / name).exists(), (page.name, name)
        for link in re.findall(r"\]\(([^)#:\s]+)(?:#[^)]*)?\)", text):  # relative links resolve
            assert (page.parent / link).exists(), (page.name, link)


def test_the_site_home_is_the_readme():
    """Structure guard: docs/index.md is written from the README by tools/readme.py."""
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    assert index == readme_tool().index_text(README)


def test_the_readme_is_short_and_links_every_guide():
    assert len(README.splitlines()) <= 400
    for guide in GUIDE:
        if guide != "README":
            assert f"docs/guides/{guide}.md" in README or guide == "development", guide


def test_the_own_robot_commands_run_as_written(tmp_path, monkeypatch, capsys):
    """the section "Your own robot and data" — its Python block, then every command of
    its marked block in order, in one folder (each may use what the ones before it wrote)."""
    import shlex
    import shutil

    pytest.importorskip("pybullet")
    pytest.importorskip("rosbags")
    pytest.importorskip("plotly")
    from bidmp.cli import main

    section = GUIDE["your-data"]
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
