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

_getattr, __dir__ = exports(__name__, __file__, globals(), ("__version__", *_SUBPACKAGES))


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


# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from ._checks import (
        Limits,
        MissingExtraError,
        NotFittedError,
        TaskRefusal,
        get_limits,
        set_limits,
    )
    from .demonstrations.preparation import prepare
    from .extension.extend import extend_demonstration
    from .extension.segmentation import Segmentation, segment
    from .extension.similarity import frechet_distance, frechet_similarity
    from .incremental.bidmp import BiDMP, forgetting
    from .incremental.bls import BLS
    from .incremental.cartesian import CartesianBiDMP
    from .io import ModelFileError
    from .io import load_model as load
    from .io import save_model as save
    from .primitives.avoidance import SceneAvoidance
    from .primitives.cartesian import CartesianDMP
    from .primitives.dmp import DMP
    from .primitives.limits import MotionLimits
    from .primitives.timing import Trajectory, time_scale
    from .scene import Clearance, Scene, Tool
    from .tasks.evaluation import evaluate
