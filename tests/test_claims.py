"""Every figure the prose gives from a committed result equals that result.

The README, the guides (docs/guides/*.md) and CHANGELOG.md's current version section quote
numbers from the committed results (docs/results/*.md and *.json, written by the make targets
that make them). ``CLAIMS`` ties each quoted number to its source: the page, the text around the
number with the number written as ``{}``, and per ``{}`` the result file and the field it comes
from. A number is checked by value at the precision the prose prints it (0.994 is a CL_score of
0.99390...; 663 a mean DTW of 663.1). The README once said CL_score 0.985 where the committed
table said 0.994.

A new number next to a result must be tied too: every number the prose puts next to a result
(tests/claims.py says which: a sentence naming a measure such as CL_score, ACC, DTW, RMSE or
"per nut", a paragraph citing a committed result file, the prose right after a generated table)
is claimed here, or listed in ``NOT_RESULTS`` with the reason it is not a committed result (a
setting, a published figure, a benchmark's timing, a number no committed file holds). The tables
the documentation copies whole are tests/test_readme.py's (generated blocks).
"""

from __future__ import annotations

import json
import re
import statistics

import pytest
from claims import (
    RESULTS,
    Claim,
    D,
    J,
    M,
    NotResult,
    X,
    claim,
    markdown_tables,
    normalised,
    pages,
    parse_number,
    result_numbers,
    same_at_precision,
)

README, CLFD, CHANGELOG = "README.md", "docs/guides/clfd.md", "CHANGELOG.md"
LASA_GUIDE, REPRODUCING = "docs/guides/lasa.md", "docs/guides/reproducing.md"


def _json(name: str):
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def _column(name: str, column: str, rows=None, table: int = 0) -> list[float]:
    """The numbers of ``column`` in the ``table``-th table of a committed Markdown result that
    has it (the rows named in ``rows``, or all)."""
    found = [t for t in markdown_tables(name) if column in t[0]][table]
    index = found[0].index(column)
    return [
        parse_number(re.findall(r"[−-]?\d+(?:\.\d+)?", cells[index])[0])[0]
        for cells in found[1:]
        if rows is None or cells[0] in rows
    ]


def _lasa(metric: str, method: str, case: str) -> D:
    """lasa.md's median of ``metric`` for ``method`` and ``case`` (its tables, one per metric)."""

    def read():
        text = (RESULTS / "lasa.md").read_text(encoding="utf-8")
        section = text.split(f"**{metric}**", 1)[1].split("\n**", 1)[0]
        for line in section.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if cells[0] == method:
                header = ["method", "reproduction", "near", "far"]
                return parse_number(cells[header.index(case)].split(" ")[0])[0]
        raise KeyError((metric, method, case))

    return D(f"lasa.md: {metric}, {method}, {case} (the median)", read)


def _clfd(dataset: str, method: str, *path) -> J:
    name = "clfd.json" if dataset == "lasa" else "clfd_robottasks.json"
    return J(name, "methods", method, *path)


def _metric(dataset: str, method: str, key: str) -> J:
    return _clfd(dataset, method, "metrics", "dtw", key)


def _seed_range(dataset: str, method: str, end) -> D:
    name = "clfd.json" if dataset == "lasa" else "clfd_robottasks.json"
    return D(
        f"{name}: seeds/{method}/*/metrics/dtw/CL_score, {end.__name__}",
        lambda: end(r["metrics"]["dtw"]["CL_score"] for r in _json(name)["seeds"][method]),
    )


def _mean_cycle(name: str) -> D:
    return D(f"{name}: the mean of 'cycle s'", lambda: statistics.mean(_column(name, "cycle s")))


def _lasa_row(method: str, text: str) -> Claim:
    """A row of the guide's LASA table: ACC, BWT, REM, MS, CL_score, mean DTW."""
    sources = [_metric("lasa", method, k) for k in ("ACC", "BWT", "REM", "MS", "CL_score")]
    return claim(CLFD, text, *sources, _clfd("lasa", method, "mean_dtw_over_tasks_seen", -1))


def _pose_row(method: str, text: str, score=None) -> Claim:
    """A row of the guide's RoboTasks9 table: ACC, MS, CL_score, median position DTW, median
    orientation error."""
    sources = [_metric("robottasks", method, "ACC"), _metric("robottasks", method, "MS")]
    sources += score or [_metric("robottasks", method, "CL_score")]
    sources += [
        _clfd("robottasks", method, "medians_after_last_task", "dtw"),
        _clfd("robottasks", method, "medians_after_last_task", "orientation"),
    ]
    return claim(CLFD, text, *sources)


# The published figures the protocol compares with (Auddy et al.; test_clfd.py checks the
# committed dmp-library row against them)
OUTSIDE = {"mean DTW": 1163.0, "ACC": 0.897, "CL_score": 0.81}


def _outside_gap(key: str, read) -> D:
    return D(
        f"clfd.json dmp-library's {key} against the outside figure {OUTSIDE[key]:g}, %",
        lambda: 100 * abs(read() - OUTSIDE[key]) / OUTSIDE[key],
    )


def _capacity(nodes, *path, seed=0) -> D:
    """clfd_capacity.json: the field ``path`` of bidmp-continual's row at ``nodes`` and ``seed``
    (``nodes`` None: the map library's row)."""

    def read():
        rows = _json("clfd_capacity.json")["rows"]
        value = next(
            r for r in rows if r["nodes"] == nodes and (nodes is None or r["seed"] == seed)
        )
        for key in path:
            value = value[key]
        return float(value)

    where = "map-library" if nodes is None else f"{nodes} nodes, seed {seed}"
    return D(f"clfd_capacity.json: {where}, {'/'.join(map(str, path))}", read)


def _capacity_span(nodes, read, end, scale=1.0) -> D:
    """The ``end`` (min or max) over the seeds of ``read(row)`` for ``nodes`` in
    clfd_capacity.json."""

    def value():
        rows = [r for r in _json("clfd_capacity.json")["rows"] if r["nodes"] == nodes]
        return end(read(r) for r in rows) * scale

    return D(f"clfd_capacity.json: {nodes} nodes, {end.__name__} over the seeds", value)


def _spans(nodes, key: str, scale: float = 1.0) -> tuple[D, D]:
    """The least and the largest ``key`` over the seeds at ``nodes`` (clfd_capacity.json)."""
    return tuple(_capacity_span(nodes, lambda r: r[key], end, scale) for end in (min, max))


def _ratio(nodes) -> D:
    return D(
        f"clfd_capacity.json: every number kept at {nodes} nodes over the map library's",
        lambda: _capacity(nodes, "kept").read() / _capacity(None, "kept").read(),
    )


def _median_ms(name: str) -> D:
    return D(
        f"{name}: the median of bidmp-continual's training_time_s, ms",
        lambda: (
            1e3 * statistics.median(_json(name)["methods"]["bidmp-continual"]["training_time_s"])
        ),
    )


LIBFRANKA_ALL = ("libfranka.md", "all")
KEEP = 'bidmp, approach "keep" (default)'

CLAIMS = [
    # -- README --------------------------------------------------------------------------------
    claim(
        README,
        "at the limits ({} streams just inside and just outside every limit of every joint) {} "
        "judged alike",
        M(*LIBFRANKA_ALL, "streams"),
        M(*LIBFRANKA_ALL, "agree"),
    ),
    claim(
        README,
        "a fixed-size ridge memory of their maps: ACC {}, CL_score {}, yet larger",
        _metric("lasa", "bidmp-continual", "ACC"),
        _metric("lasa", "bidmp-continual", "CL_score"),
    ),
    # -- the CLFD guide: the protocol ------------------------------------------------------------
    claim(
        CLFD,
        "(LASA: DTW {}, Fréchet {}, swept area {})",
        J("clfd.json", "thresholds", "dtw"),
        J("clfd.json", "thresholds", "frechet"),
        J("clfd.json", "thresholds", "area"),
    ),
    claim(
        CLFD,
        "published best's medians (position DTW {}×10³, orientation {} rad)",
        J("clfd_robottasks.json", "thresholds", "dtw", scale=1e-3),
        J("clfd_robottasks.json", "thresholds", "orientation"),
    ),
    claim(
        CLFD,
        "H₂₆/26 = {} on LASA, H₉/9 = {} on RoboTasks9",
        _metric("lasa", "dmp-library", "MS"),
        _metric("robottasks", "dmp-library", "MS"),
    ),
    claim(
        CLFD,
        "at least the published hypernetwork's {} M parameters",
        X("clfd.md", r"hypernetwork's ([\d,]+) parameters", scale=1e-6),
    ),
    # -- the CLFD guide: the LASA table ---------------------------------------------------------
    _lasa_row("dmp-library", "on its mean demonstration) | {} | {} | {} | {} | {} | {} |"),
    _lasa_row("finetune", "forgetting by construction) | {} | {} | {} | {} | {} | {} |"),
    claim(
        CLFD,
        "a BLS block per new task) | {} | {} | {} | {} | {}–{} | {} |",
        *[_metric("lasa", "bidmp-library", k) for k in ("ACC", "BWT", "REM", "MS")],
        _seed_range("lasa", "bidmp-library", min),
        _seed_range("lasa", "bidmp-library", max),
        _clfd("lasa", "bidmp-library", "mean_dtw_over_tasks_seen", -1),
    ),
    _lasa_row("promp-library", "conditioned on the start) | {} | {} | {} | {} | {} | {} |"),
    _lasa_row("bidmp-continual", "its conditioned ProMP) | {} | {} | {} | {} | {} | {} |"),
    # -- the CLFD guide: what bidmp-continual is ------------------------------------------------
    claim(
        CLFD,
        "(the same accuracy and DTW; BWT {} over all 26)",
        _metric("lasa", "bidmp-continual", "BWT"),
    ),
    claim(
        CLFD,
        "A reproduction reads {} numbers on LASA where the plain library of the same 26 maps "
        "(`map-library`) keeps {}, and learning the next task needs the normal equations A and B "
        "too ({} more)",
        _clfd("lasa", "bidmp-continual", "model_size", -1),
        _capacity(None, "kept"),
        _capacity(64, "numbers", "normal_equations"),
    ),
    # -- the CLFD guide: the capacity sweep (clfd_capacity.json) --------------------------------
    claim(
        CLFD,
        "At 20 nodes each stored map is {}–{} % off (the median over the tasks, over three draws "
        "of the nodes), ACC {}–{} and BWT {} to {}; at 8 nodes {}–{} % off and ACC {}–{}.",
        *_spans(20, "map_error_median", 100),
        *_spans(20, "ACC"),
        *_spans(20, "BWT"),
        *_spans(8, "map_error_median", 100),
        *_spans(8, "ACC"),
    ),
    claim(
        CLFD,
        "At 24 nodes its weights ({} numbers) are fewer than the maps ({}), and the median map is "
        "still {}–{} % off (ACC {}–{}).",
        _capacity(24, "reproduced_from"),
        _capacity(None, "kept"),
        *_spans(24, "map_error_median", 100),
        *_spans(24, "ACC"),
    ),
    claim(
        CLFD,
        "the rows are the library's (ACC {}, mean DTW {}), from {} numbers, {} with the normal "
        "equations ({}× the library); at the protocol's 64 nodes {} ({}×).",
        _capacity(None, "ACC"),
        _capacity(None, "mean_dtw"),
        _capacity(26, "reproduced_from"),
        _capacity(26, "kept"),
        _ratio(26),
        _capacity(64, "kept"),
        _ratio(64),
    ),
    claim(
        CLFD,
        "whatever that size ({} parameters on RoboTasks9)",
        _clfd("robottasks", "bidmp-continual", "model_size", -1),
    ),
    claim(
        CLFD,
        "It trains in a median {} ms (LASA) and {} ms (RoboTasks9) a task on one core",
        _median_ms("clfd.json"),
        _median_ms("clfd_robottasks.json"),
    ),
    # -- the CLFD guide: the RoboTasks9 table ---------------------------------------------------
    _pose_row("dmp-library", "| `dmp-library` | {} | {} | {} | {} | {} |"),
    _pose_row(
        "bidmp-library",
        "| `bidmp-library` | {} | {} | {}–{} | {} | {} |",
        [_seed_range("robottasks", "bidmp-library", min)]
        + [_seed_range("robottasks", "bidmp-library", max)],
    ),
    _pose_row("promp-library", "| `promp-library` | {} | {} | {} | {} | {} |"),
    _pose_row("bidmp-continual", "| `bidmp-continual` | {} | {} | {} | {} | {} |"),
    claim(
        CLFD,
        "| published best (hypernetwork, stable NODE) | | | | ≈ {}×10³ | ≈ {} |",
        J("clfd_robottasks.json", "published_best", "median_dtw", scale=1e-3),
        J("clfd_robottasks.json", "published_best", "median_orientation"),
    ),
    # -- the CLFD guide: against the outside figures --------------------------------------------
    claim(
        CLFD,
        "bidmp's `dmp-library` gives {}, {} and {} (within {} %, {} % and {} %)",
        _clfd("lasa", "dmp-library", "mean_dtw_over_tasks_seen", -1),
        _metric("lasa", "dmp-library", "ACC"),
        _metric("lasa", "dmp-library", "CL_score"),
        _outside_gap(
            "mean DTW",
            lambda: _json("clfd.json")["methods"]["dmp-library"]["mean_dtw_over_tasks_seen"][-1],
        ),
        _outside_gap(
            "ACC", lambda: _json("clfd.json")["methods"]["dmp-library"]["metrics"]["dtw"]["ACC"]
        ),
        _outside_gap(
            "CL_score",
            lambda: _json("clfd.json")["methods"]["dmp-library"]["metrics"]["dtw"]["CL_score"],
        ),
    ),
    claim(
        CLFD,
        "{} at 40, 1128 at 50 kernels",
        _clfd("lasa", "dmp-library", "mean_dtw_over_tasks_seen", -1),
    ),
    claim(
        CLFD,
        "reaches a mean DTW of about {}×10³ on LASA",
        J("clfd.json", "published_best", "mean_dtw", scale=1e-3),
    ),
    # -- the CHANGELOG ---------------------------------------------------------------------------
    claim(
        CHANGELOG,
        "LASA CL_score {}, ACC {}, BWT {}, mean DTW {};",
        _metric("lasa", "bidmp-continual", "CL_score"),
        _metric("lasa", "bidmp-continual", "ACC"),
        _metric("lasa", "bidmp-continual", "BWT"),
        _clfd("lasa", "bidmp-continual", "mean_dtw_over_tasks_seen", -1),
    ),
    claim(
        CHANGELOG,
        "(at 20 nodes each stored map is {}–{} % off, the median)",
        *_spans(20, "map_error_median", 100),
    ),
    claim(
        CHANGELOG,
        "in more numbers than the maps ({} at 64 nodes against {})",
        _capacity(64, "kept"),
        _capacity(None, "kept"),
    ),
    claim(
        CHANGELOG,
        "RoboTasks9 median position DTW {}, orientation error {} rad)",
        _clfd("robottasks", "bidmp-continual", "medians_after_last_task", "dtw"),
        _clfd("robottasks", "bidmp-continual", "medians_after_last_task", "orientation"),
    ),
    claim(
        CHANGELOG,
        "judges bidmp against libfranka at the limits: {} streams, a pair just",
        M(*LIBFRANKA_ALL, "streams"),
    ),
    # -- the fuzz campaign ---------------------------------------------------------------------
    claim(
        "docs/guides/command-line.md",
        "{} calls over {} entry points, {} of them with two arguments changed",
        J("fuzz.json", "calls"),
        J("fuzz.json", "entry_points"),
        J("fuzz.json", "pairs"),
    ),
    claim(
        "docs/guides/command-line.md",
        "but for {} known ones listed there as `known_defects`",
        D(
            "fuzz.json: the number of known_defects",
            lambda: len(_json("fuzz.json")["known_defects"]),
        ),
    ),
    # -- geometry, scenarios, simulation -------------------------------------------------------
    claim(
        "docs/guides/geometry.md",
        "The plain DMP ends within {} mm of only the 8 nearest nuts",
        J("sim_results.json", "success_threshold"),
    ),
    claim(
        "docs/guides/geometry.md",
        "the kept approach passes the neighbouring nuts at {} mm or more, the plain DMP at {} mm",
        M("tasks.md", ("nut-unscrewing", KEEP), "to the other targets' parts"),
        M("tasks.md", ("nut-unscrewing", "dmp"), "to the other targets' parts"),
    ),
    claim(
        "docs/guides/scenarios.md",
        "passes {} mm over the plate at an engaged nut",
        M("tasks.md", ("nut-unscrewing", KEEP), "worst clearance mm (part)"),
    ),
    claim(
        "docs/guides/simulation.md",
        "the *measured* tool path ends within {} mm",
        J("sim_results.json", "success_threshold"),
    ),
    claim(
        "docs/guides/simulation.md",
        "The plain DMP's motions to the 6 far nuts end more than {} mm from them",
        J("sim_results.json", "success_threshold"),
    ),
    claim(
        "docs/guides/simulation.md",
        "stays within the limits (jerk at most {} of it)",
        D(
            "sim_results.json: the largest peak_joint_jerk of a motion that ran",
            lambda: max(
                t["peak_joint_jerk"]
                for m in _json("sim_results.json")["methods"].values()
                for t in m["targets"].values()
                if t["ran"]
            ),
        ),
    ),
    # -- the job ---------------------------------------------------------------------------------
    claim(
        "docs/guides/job.md",
        "within the limits; {} s per nut (unscrewing {} s for {} turns",
        J("job_results.json", "totals", "cycle_s_mean"),
        M("job.md", "3", "unscrew s"),
        D(
            "job_results.json: the unscrew phase's note, its turns",
            lambda: float(
                re.search(
                    r"([\d.]+) turns",
                    next(
                        p["note"]
                        for p in _json("job_results.json")["targets"][0]["phases"]
                        if p["phase"] == "unscrew"
                    ),
                ).group(1)
            ),
        ),
    ),
    claim(
        "docs/guides/your-cell.md",
        "every command within its limits, {} s per nut ([docs/results/job_xarm6.md]",
        _mean_cycle("job_xarm6.md"),
    ),
    claim(
        "docs/guides/your-cell.md",
        "within its limits, {} s per nut ([docs/results/job_ur5.md]",
        _mean_cycle("job_ur5.md"),
    ),
    # -- libfranka -------------------------------------------------------------------------------
    claim(
        "docs/guides/libfranka.md",
        "just outside its threshold: {} streams, judged by bidmp",
        M(*LIBFRANKA_ALL, "streams"),
    ),
    claim(
        "docs/guides/libfranka.md",
        "**{} of {} agree**: every range, acceleration and jerk stream on all seven joints, {} of "
        "{} flat-velocity and {} of {} position-based velocity streams (the run took {} s).",
        M(*LIBFRANKA_ALL, "agree"),
        M(*LIBFRANKA_ALL, "streams"),
        M("libfranka.md", "velocity", "agree"),
        M("libfranka.md", "velocity", "streams"),
        M("libfranka.md", "position-based velocity", "agree"),
        M("libfranka.md", "position-based velocity", "streams"),
        X("libfranka.md", r"motion limits enforced\) in (\d+) s"),
    ),
    # -- LASA ----------------------------------------------------------------------------------
    claim(
        LASA_GUIDE,
        "({} and {} mm median against {} for a DMP of the demonstration itself)",
        _lasa("rmse", "promp", "reproduction"),
        _lasa("rmse", "dmp-multi", "reproduction"),
        _lasa("rmse", "dmp-paper", "reproduction"),
    ),
    claim(
        LASA_GUIDE,
        "(RMSE {} mm median, the robot-protocol DMP of one demonstration {}, the paper's DMP {})",
        _lasa("rmse", "dmp-multi", "far"),
        _lasa("rmse", "dmp-robot", "far"),
        _lasa("rmse", "dmp-paper", "far"),
    ),
    claim(LASA_GUIDE, "bends like the paper's DMP ({} mm)", _lasa("rmse", "promp", "far")),
    claim(
        LASA_GUIDE,
        "reaches it: median {} mm near and {} mm far.",
        _lasa("endpoint_error", "bidmp", "near"),
        _lasa("endpoint_error", "bidmp", "far"),
    ),
    claim(
        LASA_GUIDE,
        "misses far goals by {} mm.",
        _lasa("endpoint_error", "dmp-paper", "far"),
    ),
    claim(
        LASA_GUIDE,
        "RMSE rose from 0.70/1.76 to {}/{} mm",
        _lasa("rmse", "dmp-robot", "near"),
        _lasa("rmse", "dmp-robot", "far"),
    ),
    claim(
        LASA_GUIDE,
        "(near/far RMSE 2.53/13.5 → {}/{} mm",
        _lasa("rmse", "bidmp", "near"),
        _lasa("rmse", "bidmp", "far"),
    ),
    claim(
        LASA_GUIDE,
        "its reproduction RMSE is {} (the table",
        _lasa("rmse", "dmp-robot", "reproduction"),
    ),
    # -- the paper's tables ----------------------------------------------------------------------
    claim(
        REPRODUCING,
        "(8/14 = {} %) with a maximum error of {} mm",
        M("table4.md", "DMP (fixed horizon)", "success rate (ours / paper)"),
        M("table4.md", "DMP (fixed horizon)", "max error mm (ours / paper)"),
    ),
    claim(
        REPRODUCING,
        "column lower: {}–{} and {}–{} mm)",
        D("table4.md: Bi-DMP, nuts 9, 11, 12, 14, min", lambda: min(_nuts((9, 11, 12, 14)))),
        D("table4.md: Bi-DMP, nuts 9, 11, 12, 14, max", lambda: max(_nuts((9, 11, 12, 14)))),
        D("table4.md: Bi-DMP, nuts 10, 13, min", lambda: min(_nuts((10, 13)))),
        D("table4.md: Bi-DMP, nuts 10, 13, max", lambda: max(_nuts((10, 13)))),
    ),
    claim(
        REPRODUCING,
        "the same DMP reaches every nut (max {} mm)",
        M("table4.md", "DMP run to convergence", "max error mm (ours / paper)"),
    ),
    claim(
        REPRODUCING,
        "gives 10/14 and loses the demonstrated nut ({} mm)",
        M("table4.md", 'Bi-DMP `skill="latest"` (paper-literal)', "max error mm (ours / paper)"),
    ),
    claim(
        REPRODUCING,
        "the default) keeps it ({} mm)",
        M("table4.md", "N3", "nut skill only"),
    ),
    claim(
        REPRODUCING,
        "the nut Bi-DMP misses B6 by {} mm; after the second extended demonstration to B6 is "
        "learned on top, it misses by {} mm",
        M("table4.md", "B6", "nut skill only"),
        M("table4.md", "B6", "after the second extension to B6"),
    ),
    claim(
        REPRODUCING,
        "forgetting {} mm with `nearest` ({} and {} mm with `latest`)",
        M("table4.md", '`skill="nearest"`', "operator 2"),
        M("table4.md", '`skill="latest"`', "demonstrated operator"),
        M("table4.md", '`skill="latest"`', "operator 2"),
    ),
    claim(
        REPRODUCING,
        "over all cases ({} vs {})",
        D("table5.md: the mean of 'G-PRM it 1'", lambda: statistics.mean(_table5("G-PRM it 1"))),
        D(
            "table5.md: the mean of 'classic PRM (all iterations)'",
            lambda: statistics.mean(_table5("classic PRM (all iterations)")),
        ),
    ),
    claim(
        REPRODUCING,
        "it does not ({} vs {})",
        M("table5.md", "LASA Sshape", "G-PRM it 1"),
        M("table5.md", "LASA Sshape", "classic PRM (all iterations)"),
    ),
    claim(
        REPRODUCING,
        "(Sshape {} → {})",
        M("table5.md", "LASA Sshape", "G-PRM it 1"),
        M("table5.md", "LASA Sshape", "G-PRM best-of"),
    ),
    # -- robot-ready motion ----------------------------------------------------------------------
    claim(
        "docs/guides/robot-ready-motion.md",
        "far smaller in practice ({} mm on the {} mm move above)",
        M("robot.md", "1.13 mm", "bidmp"),
        M("robot.md", "1.13 mm", "goal"),
    ),
    claim(
        "docs/guides/robot-ready-motion.md",
        "reproduces them to {} / {} mm RMS (the table above)",
        M("robot.md", "operator1_nut3", "bidmp: RMSE"),
        M("robot.md", "operator2_nut5", "bidmp: RMSE"),
    ),
    claim(
        "docs/guides/robot-ready-motion.md",
        "over the first 50 ms acceleration and jerk stay within {}× the demonstration's own",
        D(
            "robot.md: the largest of 'bidmp: acceleration' and 'bidmp: jerk', at most",
            lambda: max(
                _column("robot.md", "bidmp: acceleration") + _column("robot.md", "bidmp: jerk")
            ),
        ).at_most(),
    ),
]


def _nuts(nuts) -> list[float]:
    table = next(t for t in markdown_tables("table4.md") if t[0][0] == "nut")
    row = next(cells for cells in table if cells[0] == "Bi-DMP")
    return [parse_number(row[table[0].index(str(n))].split(" ")[0])[0] for n in nuts]


def _table5(column: str) -> list[float]:
    return _column("table5.md", column)


def _not(page: str, reason: str, *texts: str) -> list[NotResult]:
    return [NotResult(page, text, reason) for text in texts]


SETTING = "a setting or input of the run, not its result"
PUBLISHED = "a published figure the results are compared with"
BENCHMARK = "a benchmark's measurement (the page names the script), not a committed result"
HISTORY = "what an earlier version measured"
UNCOMMITTED = "measured once by the command the page names; no committed file holds it"

NOT_RESULTS = [
    *_not("CHANGELOG.md", UNCOMMITTED, "massless `panda_link8`'s inertia: {} N m)"),
    *_not(
        "CHANGELOG.md",
        HISTORY,
        "{} of {} generated streams are judged alike (`make franka-agreement`",
        "`--streams` is gone with the {} mixed streams it sized",
    ),
    *_not("CHANGELOG.md", SETTING, "inside and just outside ({} % apart) each limit kind's"),
    *_not(CLFD, SETTING, "{} basis functions, per task"),
    *_not(
        CLFD,
        PUBLISHED,
        "one DMP per task gave mean DTW {}, ACC {} and CL_score ≈ {}",
    ),
    *_not(
        CLFD,
        "a sweep of the DMP's kernel count run once (the comment at CLFD_KERNELS), not committed",
        "({} at 25,",
        "at 40, {} at 50 kernels, where the ACC is {}, {} % above)",
    ),
    *_not(
        "docs/guides/command-line.md",
        SETTING,
        "10**{}, wrong types",
        "ragged and {}-deep nested lists",
        "`make test` runs {} of them",
        "a motion file named by {} characters",
    ),
    *_not("docs/guides/development.md", HISTORY, "resting places by up to {} mm"),
    *_not("docs/guides/geometry.md", SETTING, "diagonal piece into ({}, 25, 0)"),
    *_not(
        "docs/guides/job.md",
        UNCOMMITTED,
        "each rocked ±{} mm at {} Hz for {} s, 0 contacts, within the joint limits, {}× real time "
        "for the whole command ({} s wall for {} s simulated",
        "3/3 boxes in the rack, 0 contacts, within the limits, {} s per box",
    ),
    *_not("docs/guides/job.md", SETTING, "the drop with {} s for the nut to settle"),
    *_not(
        LASA_GUIDE,
        HISTORY,
        "RMSE rose from {}/{} to",
        "(near/far RMSE {}/{} →",
        "the table committed before issue 19 had {},",
        "(After issue 19, `make lasa` took {} s with 2 workers.)",
        "two workers were slower than one ({}×)",
        "every array above {} KiB was mapped and unmapped afresh (16 cells: {} s of kernel time "
        "against {} s)",
    ),
    *_not(
        LASA_GUIDE,
        BENCHMARK,
        "The full set ({} cells,",
        "falls on both: {} s serially, {} s on 2 workers with the cluster's start and stop "
        "counted, a **{}×** speed-up (rounds {}–{}×)",
        "Dask's own overhead is {} empty tasks/s on 2 workers ({} ms per task), against about {} "
        "s of work per cell",
    ),
    *_not(REPRODUCING, SETTING, "T = {}, α = {}, K = α) with every method", "block ({}, 25, 0)"),
    *_not(REPRODUCING, PUBLISHED, "The paper reports classic PRM below {} and G-PRM 34 % higher"),
    *_not(
        "docs/guides/library.md",
        "benchmarks/bidmp_convergence.py's tables, printed, not committed",
        "bought {} mm of reproduction (RMSE {} against {} mm)",
    ),
    *_not(
        "docs/guides/rhythmic.md",
        SETTING,
        "On 20 seeded recordings ({}-1.8 Hz, {}-1000 Hz stamps, 6 periods, ramps, {} mm noise)",
    ),
    *_not(
        "docs/guides/rhythmic.md",
        BENCHMARK,
        "reproduction RMSE {} % of the amplitude for bidmp (worst {} %) against {} % for pydmps "
        "(worst {} %), the frequency within {} % (worst {} %), fit + one period 16 ms against "
        "pydmps' 47 ms ({}×",
    ),
    *_not(
        "docs/guides/robot-ready-motion.md",
        SETTING,
        "at {} Hz and 1 kHz, for its goal and goals {} mm away",
        "from its goal at {} times the demonstrated duration",
    ),
    *_not("docs/guides/robot-ready-motion.md", PUBLISHED, "Cartesian jerk limit, {} m/s³"),
    *_not(
        "docs/guides/several.md",
        "a number of the page's own, measured once, not committed",
        "gives an RMSE of {} mm from the shifted demonstration at 1e-6, 37 mm at the default 1e-2 "
        "and 15 mm at {} (what the LASA benchmark uses)",
    ),
    *_not(
        "docs/guides/several.md",
        BENCHMARK,
        "the two learned means agree to {} mm (RMSE)",
        "the mean's RMSE is {} mm for both, conditioned on the held-out start and goal {} mm for "
        "bidmp against {} mm",
        "fitting is {}× faster ({} ms, ridge against EM), conditioning and the mean at {} phases "
        "{}×",
    ),
    *_not(
        "docs/guides/simulation.md",
        PUBLISHED,
        "(Franka's {}, {}, {}, {}, {}, {}, {} rad/s³)",
    ),
    *_not(
        "docs/guides/speed.md",
        SETTING,
        "on the {} × {} basis",
    ),
    *_not(
        "docs/guides/speed.md",
        BENCHMARK,
        "the rollout's forcing: {} ms alone",
        "the interleaved benchmark's {} ms against {} alone",
        "(the solve {} ms faster alone",
        "fit + trajectory took {}–{} ms instead of {} (tried again later: {}–{} ms medians against "
        "a steady {}–{} with one thread)",
        "Even then the benchmark measured {} ms, {}–{}× and {}–{}×",
    ),
    *_not(
        "docs/guides/speed.md",
        HISTORY,
        "(clearance by {} mm, a nut's final position by {} mm",
    ),
    *_not("docs/guides/your-cell.md", SETTING, "(5× and {}× the speed limit per second)"),
    *_not(
        "docs/guides/your-data.md",
        UNCOMMITTED,
        "14/14 nuts in the bin, 0 contacts, within its limits, {} s per nut.",
    ),
    *_not(CHANGELOG, HISTORY, "unrendered ({} mm against {} mm on the far nut)"),
]


def _id(item) -> str:
    return f"{item.page}: {item.text[:50]}"


@pytest.mark.parametrize("item", CLAIMS + NOT_RESULTS, ids=_id)
def test_each_claim_is_on_its_page(item):
    """A claim the prose no longer makes (its text changed) is stale here: say what it says now."""
    text = normalised(pages()[item.page])
    found = item.pattern().findall(text)
    assert found, f"{item.page} no longer says {item.text!r}: update tests/test_claims.py"
    if isinstance(item, Claim):
        assert len(found) == 1, f"{item.page} says {item.text!r} {len(found)} times: lengthen it"


@pytest.mark.parametrize("item", CLAIMS, ids=_id)
def test_each_claimed_number_equals_its_committed_result(item):
    match = item.pattern().search(normalised(pages()[item.page]))
    if match is None:
        pytest.skip("not on its page (test_each_claim_is_on_its_page says so)")
    wrong = []
    for printed, source in zip(match.groups(), item.sources):
        value = source.read()
        if not source.holds(printed, value):
            wrong.append(f"{printed} but {source.what} is {value!r}")
    assert not wrong, f"{item.page}: {item.text!r}: " + "; ".join(wrong)


@pytest.mark.parametrize("page", list(pages()))
def test_every_number_next_to_a_result_is_tied_to_its_source(page):
    """A number added to the prose next to a result, without its source in CLAIMS or its reason
    in NOT_RESULTS, fails here."""
    text = normalised(pages()[page])
    covered = set()
    for item in CLAIMS + NOT_RESULTS:
        if item.page == page:
            for match in item.pattern().finditer(text):
                covered |= (
                    {match.span(g) for g in range(1, match.lastindex + 1)}
                    if (match.lastindex)
                    else set()
                )
    loose = [
        f"{number} in: {unit[:160]}"
        for start, end, number, unit in result_numbers(pages()[page])
        if (start, end) not in covered
    ]
    assert not loose, f"{page}: numbers next to a result without a source:\n" + "\n".join(loose)


# -- the machinery can fail -------------------------------------------------------------------


def test_a_number_is_its_source_only_at_the_precision_printed():
    assert same_at_precision("0.994", 0.9939006) and not same_at_precision("0.985", 0.9939006)
    assert same_at_precision("663", 663.117) and not same_at_precision("664", 663.117)
    assert same_at_precision("0.000", -1e-17) and same_at_precision("−0.918", -0.91758)
    assert same_at_precision("40 256", 40256) and same_at_precision("1,800,000", 1.8e6)
    assert not same_at_precision("2.70", 2.6915) and not same_at_precision("0.012", 0.01117)
    assert parse_number("1 124") == (1124.0, 0) and parse_number("0.0064") == (0.0064, 4)
    bound = D("a bound", lambda: 0.3192).at_most()
    assert bound.holds("0.33", 0.3192) and not bound.holds("0.31", 0.3192)


def test_the_numbers_next_to_a_result_are_found():
    """Planted prose: a measure's sentence, a cited paragraph, the prose after a generated table
    and a measure's table are found; a sentence without either, inline code, a year, an issue
    and a count's denominator are not."""
    page = (
        "The socket is 25.4 mm wide. It scores CL_score 0.985 here.\n\n"
        "As [results/sim.md](../results/sim.md) says, 8.2 s and `1.5` in 2024 (issue 19).\n\n"
        "<!-- generated: docs/results/job.md -->\n| a |\n<!-- end generated -->\n\n"
        "Read it: 14/14 nuts, 7.1 s.\n\n"
        "| method | ACC |\n|---|---|\n| x | 0.919 |\n\n"
        "| method | width |\n|---|---|\n| x | 3.25 |\n\n"
        "Later 123.5 again."
    )
    found = [number for _, _, number, _ in result_numbers(page)]
    assert found == ["0.985", "8.2", "7.1", "0.919"]
    text = normalised(page)
    for start, end, number, _ in result_numbers(page):
        assert text[start:end] == number


def test_the_readme_before_this_test_is_caught():
    """The review's finding: the README said CL_score 0.985 in a sentence the test reads as a
    result's, and the committed table says otherwise."""
    sentence = (
        "- **Benchmarks**: the field's continual-learning protocol (a fixed-size BLS keeps all 26 "
        "LASA tasks: CL_score 0.985), the paper's tables reproduced"
    )
    assert [n for _, _, n, _ in result_numbers(sentence)] == ["0.985"]
    committed = _json("clfd.json")["methods"]["bidmp-continual"]["metrics"]["dtw"]["CL_score"]
    assert not same_at_precision("0.985", committed)
