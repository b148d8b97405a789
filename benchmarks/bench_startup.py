"""Start-up: how long ``bidmp --help`` and a first ``bidmp fit`` take, against ``python -c pass``.

Every command runs as a fresh process (what a user at a shell meets), the commands interleaved
round by round so that a noisy machine slows all of them alike; the median of the rounds and the
ratio to ``python -c pass`` are printed, with the import cost of ``import bidmp`` and of the first
model class and the share of it that is scikit-learn's ``sklearn.base`` (measured with
``python -X importtime``).

    python benchmarks/bench_startup.py            # 9 rounds
    python benchmarks/bench_startup.py --smoke    # 1 round (CI: the script cannot silently break)
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RECORDING = (
    Path(__file__).resolve().parent.parent
    / "src"
    / "bidmp"
    / "data"
    / "recordings"
    / "operator1_nut3.csv"
)


def _commands(scratch: Path) -> dict[str, list[str]]:
    python = sys.executable
    return {
        "python -c pass": [python, "-c", "pass"],
        "bidmp --help": [python, "-m", "bidmp", "--help"],
        "import bidmp": [python, "-c", "import bidmp"],
        "import bidmp; bidmp.DMP": [python, "-c", "import bidmp; bidmp.DMP"],
        # the peer's, interleaved with ours (the target: bidmp.DMP no slower to import)
        "import movement_primitives.dmp": [python, "-c", "import movement_primitives.dmp"],
        "bidmp fit (a 7 s recording)": [
            python,
            "-m",
            "bidmp",
            "fit",
            str(RECORDING),
            "--units",
            "mm",
            "-o",
            str(scratch / "m.npz"),
        ],
    }


def _import_cost(statement: str, module: str) -> tuple[float, float]:
    """(cumulative import time of the statement's imports, the share of ``module`` in it) in s."""
    run = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", statement],
        capture_output=True,
        text=True,
        check=True,
    )
    total = own = 0.0
    for line in run.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        _, cumulative, name = line.split("|")
        if not cumulative.strip().isdigit():
            continue
        if name.startswith(" ") and not name.startswith(
            "  "
        ):  # a top-level import of the statement
            total += int(cumulative) * 1e-6
        if name.strip() == module and (own == 0.0):
            own = int(cumulative) * 1e-6
    return total, own


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--smoke", action="store_true", help="one round")
    args = parser.parse_args()
    rounds = 1 if args.smoke else args.rounds
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    with tempfile.TemporaryDirectory() as folder:
        commands = _commands(Path(folder))
        for (
            argv
        ) in commands.values():  # warm-up: the disk cache, numba's cached kernels, __pycache__
            subprocess.run(argv, capture_output=True, env=env, check=True)
        times: dict[str, list[float]] = {name: [] for name in commands}
        for _ in range(rounds):
            for name, argv in commands.items():
                start = time.perf_counter()
                subprocess.run(argv, capture_output=True, env=env, check=True)
                times[name].append(time.perf_counter() - start)
    baseline = statistics.median(times["python -c pass"])
    print(f"start-up, median of {rounds} interleaved round(s), each command a fresh process")
    print(f"{'command':32s} {'s':>8s} {'x python -c pass':>18s}")
    for name, samples in times.items():
        median = statistics.median(samples)
        print(f"{name:32s} {median:8.3f} {median / baseline:18.1f}")
    total, sklearn = _import_cost("import bidmp; bidmp.DMP", "sklearn.base")
    print(
        f"import bidmp; bidmp.DMP: {total:.3f} s of imports (python -X importtime), of which sklearn.base "
        f"{sklearn:.3f} s ({100 * sklearn / max(total, 1e-9):.0f} %)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
