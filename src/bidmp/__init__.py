"""bidmp — one-shot Learning from Demonstration with DMPs, extended demonstrations and Bi-DMP.

The public names are imported lazily (PEP 562), so ``import bidmp`` and
``bidmp --help`` do not pay for NumPy/SciPy until a name is used.

The subpackages, in layers (each imports only from the layers above it; ``tests/test_package.py``
checks it):

1. the math — ``primitives`` (DMPs, goal systems, integrators, coupling terms, timing),
   ``extension`` (segmentation, Fréchet similarity, G-PRM, extended demonstrations),
   ``incremental`` (BLS, Bi-DMP), ``baselines`` (GMM/GMR, TP-GMM), ``scene`` (parts, clearance);
2. data and tasks — ``demonstrations`` (prepare, datasets), ``io`` (files), ``tasks`` (scenarios,
   methods, evaluation, metrics);
3. the application — ``sim`` (simulator backends), ``experiments`` (the paper's tables, LASA),
   ``plotting``;
4. the shell — ``cli``.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from ._lazy import exports
from ._version import __version__

# A library logs; the application decides what is shown (without a handler of its own, Python's
# last resort would print every warning of bidmp to stderr).
logging.getLogger(__name__).addHandler(logging.NullHandler())

# public name -> "module[:attribute]" relative to bidmp
_LAZY = {
    "DMP": "primitives.dmp",
    "Trajectory": "primitives.timing",
    "prepare": "demonstrations.prepare",
    "time_scale": "primitives.timing",
    "segment": "extension.segmentation",
    "Segmentation": "extension.segmentation",
    "frechet_distance": "extension.similarity",
    "frechet_similarity": "extension.similarity",
    "extend_demonstration": "extension.extend",
    "Scene": "scene",
    "CartesianDMP": "primitives.cartesian",
    "CartesianBiDMP": "incremental.cartesian",
    "Tool": "scene",
    "Clearance": "scene",
    "SceneAvoidance": "primitives.avoidance",
    "MissingExtraError": "_checks",
    "BLS": "incremental.bls",
    "BiDMP": "incremental.bidmp",
    "forgetting": "incremental.bidmp",
    "evaluate": "tasks.evaluation",
    "save": "io:save_model",
    "load": "io:load_model",
    "ModelFileError": "io",
    "NotFittedError": "_checks",
    "Limits": "_checks",
    "get_limits": "_checks",
    "set_limits": "_checks",
}
# the subpackages of the layout
_SUBPACKAGES = (
    "primitives",
    "demonstrations",
    "extension",
    "incremental",
    "baselines",
    "scene",
    "tasks",
    "sim",
    "experiments",
    "io",
    "plotting",
)

__all__ = ["__version__", *_LAZY, *_SUBPACKAGES]

_getattr, __dir__ = exports(__name__, _LAZY, globals())


def __getattr__(name: str):
    if name in _SUBPACKAGES:
        import importlib

        value = importlib.import_module(f"{__name__}.{name}")
        globals()[name] = value
        return value
    try:
        return _getattr(name)
    except AttributeError:
        raise AttributeError(f"module 'bidmp' has no attribute {name!r}") from None


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from ._checks import (  # noqa: F401
        Limits,
        MissingExtraError,
        NotFittedError,
        get_limits,
        set_limits,
    )
    from .demonstrations.prepare import prepare  # noqa: F401
    from .extension.extend import extend_demonstration  # noqa: F401
    from .extension.segmentation import Segmentation, segment  # noqa: F401
    from .extension.similarity import frechet_distance, frechet_similarity  # noqa: F401
    from .incremental.bidmp import BiDMP, forgetting  # noqa: F401
    from .incremental.bls import BLS  # noqa: F401
    from .incremental.cartesian import CartesianBiDMP  # noqa: F401
    from .io import ModelFileError  # noqa: F401
    from .io import load_model as load  # noqa: F401
    from .io import save_model as save  # noqa: F401
    from .primitives.cartesian import CartesianDMP  # noqa: F401
    from .primitives.dmp import DMP  # noqa: F401
    from .primitives.timing import Trajectory, time_scale  # noqa: F401
    from .scene import Clearance, Scene, Tool  # noqa: F401
