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
    assert {path for path, _ in blocks} == {"docs/results/table4.md", "docs/results/tasks.md", "docs/results/table5.md",
                                       "docs/results/figures.md", "docs/results/sim.md",
                                       "docs/results/lasa.md"}
    for path, body in blocks:
        committed = (ROOT / path).read_text(encoding="utf-8")
        assert body.strip() == committed.strip(), f"README block {path} is stale: run 'make readme'"


PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", README, re.DOTALL)


@pytest.mark.parametrize("index", range(len(PYTHON_BLOCKS)))
def test_every_python_block_runs_alone(index, tmp_path):
    result = subprocess.run([sys.executable, "-c", PYTHON_BLOCKS[index]], cwd=tmp_path, capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]


def test_the_readme_limits_table_states_the_defaults_in_force():
    import dataclasses

    import bidmp

    rows = dict(re.findall(r"^\| `(max_\w+|min_\w+)` \| ([^|]+) \|", README, re.MULTILINE))
    defaults = dataclasses.asdict(bidmp.Limits())
    assert set(rows) == set(defaults), "document every limit in the README table"
    for name, value in defaults.items():
        assert float(rows[name]) == float(value), name
