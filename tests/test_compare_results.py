"""tools/compare_results.py: committed results are compared by value — a decimal may move in its
last printed place or by a relative 1e-9, an integer (a count) may not, the words may not; JSON
floats to 1e-9, everything else exactly. Cases built here by hand, each able to fail."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

from compare_results import compare_json, compare_text, main  # noqa: E402

TABLE = "| Sshape | 1 | 0.039 | 16.2 | 14/14 | 1.5e-3 |\n"


def test_a_last_printed_digit_may_move_and_nothing_more():
    assert compare_text(TABLE, TABLE) == []
    assert compare_text(TABLE.replace("0.039", "0.040"), TABLE) == []  # one unit, last place
    assert compare_text(TABLE.replace("16.2", "16.1"), TABLE) == []
    assert compare_text(TABLE.replace("1.5e-3", "1.6e-3"), TABLE) == []
    assert compare_text(TABLE.replace("0.039", "0.041"), TABLE)  # two units
    assert compare_text(TABLE.replace("16.2", "16.4"), TABLE)
    assert compare_text(TABLE.replace("1.5e-3", "1.7e-3"), TABLE)


def test_counts_and_words_must_be_equal():
    assert compare_text(TABLE.replace("14/14", "13/14"), TABLE)  # a count one off is a result
    assert compare_text(TABLE.replace("| 1 |", "| 2 |"), TABLE)
    assert compare_text(TABLE.replace("Sshape", "WShape"), TABLE)
    assert compare_text(TABLE + TABLE, TABLE)  # a row more


def test_json_floats_to_a_relative_1e9_the_rest_exactly():
    committed = {"rmse": [0.0389, 1.0e6], "n": 14, "name": "nut", "ok": True, "zero": 0.0}
    moved = {"rmse": [0.0389 * (1 + 5e-10), 1.0e6 * (1 - 5e-10)], "n": 14, "name": "nut",
             "ok": True, "zero": 1e-13}  # fmt: skip
    assert compare_json(moved, committed) == []
    assert compare_json({**moved, "rmse": [0.0389 * (1 + 2e-9), 1.0e6]}, committed)
    assert compare_json({**moved, "n": 15}, committed)
    assert compare_json({**moved, "name": "cell"}, committed)
    assert compare_json({**moved, "ok": False}, committed)
    assert compare_json({**moved, "extra": 1}, committed)


def test_the_command_compares_two_folders(tmp_path, capsys):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "t.md").write_text(TABLE.replace("0.039", "0.040"))
    (tmp_path / "b" / "t.md").write_text(TABLE)
    (tmp_path / "a" / "t.json").write_text('{"x": 1.0}')
    (tmp_path / "b" / "t.json").write_text('{"x": 1.0000000001}')
    assert main([str(tmp_path / "a"), str(tmp_path / "b")]) == 0
    (tmp_path / "a" / "t.json").write_text('{"x": 1.1}')
    assert main([str(tmp_path / "a"), str(tmp_path / "b")]) == 1
    assert "t.json: $.x: 1.1 / 1.0000000001" in capsys.readouterr().out
