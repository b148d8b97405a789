"""Mutation testing of the compiled loops (``bidmp/_kernels.pyx``; part of ``make mutation``).

``tools/mutation.py`` plants its bugs in live Python functions; it cannot reach a compiled loop.
Here each bug is a text edit of the Cython source — an operation reordered (the last bit moves), an
off-by-one, a comparison made strict or loose, a constant or a sign convention changed — built into
a copy of the package in a temporary folder (the checkout is never touched), and the tests that
cover the loops run against that copy. A mutant the tests fail on is *killed*; a survivor must be
shown equivalent here (with the reason) or killed by a new test. Writes ``docs/mutation-kernels.md``.

Usage::

    python tools/mutation_kernels.py            # every mutant (about 10 s each), writes the report
    python tools/mutation_kernels.py --list     # the mutants, not run
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "src" / "bidmp" / "_kernels.pyx"
REPORT = ROOT / "docs" / "mutation-kernels.md"
TESTS = ("tests/test_kernels.py", "tests/primitives/test_approach.py")


@dataclass(frozen=True)
class Mutant:
    """One planted bug: ``original`` (a unique piece of the source) replaced by ``mutated``."""

    loop: str
    original: str
    mutated: str
    equivalent: str = ""  # why no test can fail on it, when none can


MUTANTS = (
    Mutant("second_order", "z0 = z1 + x * b1 - y * a1", "z0 = z1 - y * a1 + x * b1"),
    Mutant("second_order", "z1 = x * b2 - y * a2", "z1 = x * b2 + y * a2"),
    Mutant(
        "_gradient",
        "for i in range(1, n - 1):\n        out[i]",
        "for i in range(1, n - 2):\n        out[i]",
    ),
    Mutant("_gradient", "out[0] = (f[1] - f[0]) / dt", "out[0] = (f[1] - f[0]) / two_dt"),
    Mutant(
        "_running_max",
        "if values[i - 1] > values[i] or",
        "if values[i - 1] >= values[i] or",
        "where the two are equal, keeping either is the same number",
    ),
    Mutant("_blend_window", "                index = n - 1", "                index = n - 2"),
    Mutant(
        "_blend_window",
        "if not added <= share * reach:",
        "if not added < share * reach:",
        "differs only where the blend's acceleration equals the bound to the last bit",
    ),
    Mutant(
        "_straight_from",
        "i > start and along - previous < -bound",
        "i > start + 1 and along - previous < -bound",
    ),
    Mutant(
        "_straight_from",
        "if _off_chord(y, i, start, unit, &along) > bound * bound:",
        "if _off_chord(y, i, start, unit, &along) > 1.01 * bound * bound:",
    ),
    Mutant(
        "tail_start",
        "if not length > 0.0:\n                continue",
        "if not length > 1e-3:\n                continue",
    ),
    Mutant(
        "_probes_straight",
        "shares[1] = 0.5",
        "shares[1] = 0.6",
        "a probe anywhere inside the tail is a necessary condition of the whole test: only the "
        "pruning changes, never the answer",
    ),
    Mutant("goal_gate", "gate[0] = spring / K", "gate[0] = spring / K * 1.0000000000000002"),
    Mutant("goal_share", "            elif s > closing:", "            elif s >= closing:"),
    Mutant(
        "goal_share",
        "            if s >= end:",
        "            if s > end:",
        "at s = end the closing formula gives 1 - (1 - σ) S(0) = 1 exactly",
    ),
    Mutant("rest_blended", "blend = -1.0 * (elapsed", "blend = 1.0 * (elapsed"),
    Mutant("forcing_target", "offset = goal - y[0, k]", "offset = y[0, k] - goal"),
    Mutant("exact_state", "- after_y * inputs[l + 1, k]", "- after_y * inputs[l, k]"),
    Mutant("interp_columns", "out[i, k] = y[0, k] if n == 1 else value", "out[i, k] = value"),
    Mutant(
        "interp_columns",
        "while j + 1 < n and x[j + 1] <= value:",
        "while j + 1 < n and x[j + 1] < value:",
    ),
    Mutant(
        "_flipped",
        "    if q[3] != 0:\n        return q[3] < 0",
        "    if q[3] != 0:\n        return q[3] <= 0",
        "reached only with w ≠ 0, where w ≤ 0 and w < 0 agree",
    ),
    Mutant(
        "_flipped",
        "    if q[0] != 0:\n        return q[0] < 0",
        "    if q[0] != 0:\n        return q[0] > 0",
    ),
    Mutant(
        "quaternion_log",
        "scale = angle / sin(angle / 2)",
        "scale = angle / sin(angle * 0.5000000000000001)",
    ),
    Mutant(
        "quaternion_exp",
        "scale = 0.5 - angle2 / 48 + angle2 * angle2 / 3840",
        "scale = 0.5 - angle2 / 48",
    ),
    Mutant(
        "arclength",
        "squares = squares + step * step",
        "squares = squares + step * abs(step)",
    ),
    Mutant(
        "arclength",
        "            squares = 0.0\n            for k in range(n_dims):",
        "            squares = 1e-300\n            for k in range(n_dims):",
    ),
    Mutant(
        "motion_peaks",
        "change = (work[i + 1, k] - work[i, k]) / dt",
        "change = work[i + 1, k] - work[i, k]",
    ),
    Mutant(
        "motion_peaks",
        "for i in range(n - 1 - order):",
        "for i in range(n - 2 - order):",
    ),
    Mutant(
        "motion_peaks",
        "if total > peak or total != total:",
        "if total > peak:",
    ),
    Mutant(
        "motion_peaks",
        "            peak = 0.0\n            for i in range(n - 1 - order):",
        "            peak = -1.0\n            for i in range(n - 1 - order):",
    ),
    # a band's edges: the last column searched from the wrong end, NaN not mattering
    Mutant(
        "band_of",
        "for j in range(n_columns - 1, -1, -1):",
        "for j in range(n_columns):",
    ),
    Mutant(
        "band_of",
        "                if not fabs(rows[i, j]) <= bound:\n                    first[i] = j",
        "                if fabs(rows[i, j]) > bound:\n                    first[i] = j",
    ),
    # the band's products: a column off by one, a row's start dropped
    Mutant(
        "band_product",
        "total = total + values[i, j] * weights[start + j, k]",
        "total = total + values[i, j] * weights[start + j - 1, k]",
    ),
    Mutant(
        "band_transposed_product",
        "                value = values[i, j]\n                column = first[i] + j",
        "                value = values[i, j]\n                column = j",
    ),
    # the fit's input checks in one pass: a repeat taken, a rate miscounted, the uniform line moved
    Mutant("stamp_verdict", "if not t[i] > t[i - 1]:", "if not t[i] >= t[i - 1]:"),
    Mutant("stamp_verdict", "rate = (n - 1) / (t[n - 1] - t[0])", "rate = n / (t[n - 1] - t[0])"),
    Mutant(
        "stamp_verdict",
        "return 1 if high - low <= 1e-9 * (total / (n - 1)) else 2",
        "return 1 if high - low <= 1e-6 * (total / (n - 1)) else 2",
    ),
    Mutant("extent", "offset = fabs(value - y[0, k])", "offset = fabs(value - y[0, 0])"),
    Mutant(
        "all_finite",
        "            for k in range(n_dims):\n                if not fabs(values[i, k])",
        "            for k in range(n_dims - 1):\n                if not fabs(values[i, k])",
    ),
    Mutant(
        "strictly_decreasing",
        "if not values[i] < values[i - 1]:",
        "if not values[i] <= values[i - 1]:",
    ),
    # a timed trajectory's rates and the held responses: a start velocity dropped, a sample off by
    # one, the hold's weights of the wrong end, the second sample's input of the wrong sample
    Mutant(
        "exact_rates",
        "z = 0.0 if at_rest else z_first[k]",
        "z = 0.0",
    ),
    Mutant(
        "exact_rates",
        "after = (K * forcing[l + 1, k] - gate[l + 1] * offset[k]) + held[k]",
        "after = (K * forcing[l + 1, k] - gate[l] * offset[k]) + held[k]",
    ),
    Mutant(
        "foh_responses",
        "cdef double b1 = now[0] - p22 * after[0] + p12 * after[1]",
        "cdef double b1 = now[0] - p22 * after[0] + p12 * after[0]",
    ),
    Mutant(
        "foh_responses",
        "+ after[0] * inputs[row, 1]",
        "+ after[0] * inputs[row, 2]",
    ),
)


def _build(package: Path) -> None:
    """Compile ``package``'s ``_kernels.pyx`` in place, as setup.py does (no fused multiply-adds)."""
    script = (
        "from setuptools import Extension, setup\n"
        "from Cython.Build import cythonize\n"
        "setup(ext_modules=cythonize([Extension('bidmp._kernels', ['bidmp/_kernels.pyx'], "
        "extra_compile_args=['-O2', '-ffp-contract=off'])], quiet=True), "
        "script_args=['build_ext', '--inplace', '-q'])\n"
    )
    subprocess.run(
        [sys.executable, "-c", script], cwd=package.parent, check=True, capture_output=True
    )


def _copy_package(folder: Path) -> Path:
    """A copy of ``src/bidmp`` in ``folder`` without its compiled module: (folder/bidmp)."""
    target = folder / "bidmp"
    shutil.copytree(
        ROOT / "src" / "bidmp",
        target,
        ignore=shutil.ignore_patterns("__pycache__", "*.so", "_kernels.c"),
    )
    return target


def _killed(package: Path) -> bool:
    """Whether the kernels' tests fail against the package in ``package``."""
    env = dict(os.environ, PYTHONPATH=str(package.parent))
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *TESTS],
        cwd=ROOT,
        env=env,
        capture_output=True,
    )
    return result.returncode != 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="print the mutants, do not run them")
    args = parser.parse_args(argv)
    source = SOURCE.read_text(encoding="utf-8")
    for mutant in MUTANTS:
        if source.count(mutant.original) != 1:
            print(
                f"mutation_kernels: {mutant.loop}: {mutant.original!r} is not one place in {SOURCE.name}"
            )
            return 2
    if args.list:
        for mutant in MUTANTS:
            print(f"{mutant.loop}: {mutant.original.strip()!r} -> {mutant.mutated.strip()!r}")
        return 0
    began = time.monotonic()
    rows = []
    with tempfile.TemporaryDirectory(prefix="bidmp-mutants-") as scratch:
        package = _copy_package(Path(scratch))
        _build(package)
        if _killed(package):  # the unmutated copy must pass, or every mutant would look killed
            print("mutation_kernels: the tests fail on the unmutated copy")
            return 2
        for mutant in MUTANTS:
            (package / "_kernels.pyx").write_text(
                source.replace(mutant.original, mutant.mutated), encoding="utf-8"
            )
            _build(package)
            killed = _killed(package)
            rows.append((mutant, killed))
            print(
                f"{'killed' if killed else 'SURVIVED'}: {mutant.loop}: {mutant.mutated.strip()[:70]}",
                flush=True,
            )
    survived = [mutant for mutant, killed in rows if not killed and not mutant.equivalent]
    equivalent = [mutant for mutant, killed in rows if not killed and mutant.equivalent]
    lines = [
        "# Mutation testing of the compiled loops",
        "",
        "Written by `make mutation` (`python tools/mutation_kernels.py`); do not edit. Each mutant is "
        "one bug planted in `src/bidmp/_kernels.pyx`, built into a copy of the package, and the tests "
        f"that cover the loops ({', '.join(f'`{test}`' for test in TESTS)}) run against it.",
        "",
        f"{len(rows)} mutants: {len(rows) - len(survived) - len(equivalent)} killed, "
        f"{len(equivalent)} equivalent, {len(survived)} survived, in {(time.monotonic() - began) / 60:.1f} min.",
        "",
        "| loop | planted bug | outcome |",
        "|---|---|---|",
    ]
    for mutant, killed in rows:
        outcome = (
            "killed"
            if killed
            else (f"equivalent: {mutant.equivalent}" if mutant.equivalent else "**not killed**")
        )
        before, after = next(
            (old.strip(), new.strip())
            for old, new in zip(mutant.original.splitlines(), mutant.mutated.splitlines())
            if old != new
        )
        change = f"`{before}` → `{after}`"
        lines.append(f"| `{mutant.loop}` | {change} | {outcome} |")
    REPORT.write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {REPORT.relative_to(ROOT)}")
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
