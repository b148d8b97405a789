"""bidmp — one-shot Learning from Demonstration with DMPs, extended demonstrations and Bi-DMP.

The public names of SPEC §10 are imported lazily (PEP 562), so ``import bidmp`` and
``bidmp --help`` do not pay for NumPy/SciPy until a name is used.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

__version__ = "0.4.0"

# public name -> (module, attribute)
_LAZY = {
    "DMP": ("bidmp.dmp", "DMP"),
    "Trajectory": ("bidmp.timing", "Trajectory"),
    "prepare": ("bidmp.timing", "prepare"),
    "time_scale": ("bidmp.timing", "time_scale"),
    "segment": ("bidmp.segmentation", "segment"),
    "Segmentation": ("bidmp.segmentation", "Segmentation"),
    "frechet_distance": ("bidmp.similarity", "frechet_distance"),
    "frechet_similarity": ("bidmp.similarity", "frechet_similarity"),
    "extend_demonstration": ("bidmp.extension", "extend_demonstration"),
    "Scene": ("bidmp.geometry", "Scene"),
    "CartesianDMP": ("bidmp.cartesian", "CartesianDMP"),
    "CartesianBiDMP": ("bidmp.cartesian", "CartesianBiDMP"),
    "Tool": ("bidmp.geometry", "Tool"),
    "Clearance": ("bidmp.geometry", "Clearance"),
    "MissingExtraError": ("bidmp._checks", "MissingExtraError"),
    "BLS": ("bidmp.bls", "BLS"),
    "BiDMP": ("bidmp.incremental", "BiDMP"),
    "forgetting": ("bidmp.incremental", "forgetting"),
    "evaluate": ("bidmp.evaluation", "evaluate"),
    "save": ("bidmp.io", "save_model"),
    "load": ("bidmp.io", "load_model"),
    "ModelFileError": ("bidmp.io", "ModelFileError"),
    "NotFittedError": ("bidmp._checks", "NotFittedError"),
    "Limits": ("bidmp._checks", "Limits"),
    "get_limits": ("bidmp._checks", "get_limits"),
    "set_limits": ("bidmp._checks", "set_limits"),
}
_SUBMODULES = (
    "dmp", "timing", "segmentation", "similarity", "roadmap", "bls", "extension", "incremental", "geometry", "cartesian",
    "baselines", "datasets", "io", "scenarios", "metrics", "evaluation", "reproduce", "plotting", "sim", "benchmark",
)

__all__ = ["__version__", *_LAZY, *_SUBMODULES]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs only
    from . import bls, datasets, dmp, evaluation, extension, geometry, incremental, io, metrics, plotting, reproduce, roadmap, segmentation, similarity  # noqa: F401
    from .bls import BLS  # noqa: F401
    from .incremental import BiDMP, forgetting  # noqa: F401
    from ._checks import Limits, NotFittedError, get_limits, set_limits  # noqa: F401
    from .dmp import DMP  # noqa: F401
    from .timing import Trajectory, prepare, time_scale  # noqa: F401
    from .extension import extend_demonstration  # noqa: F401
    from .geometry import Clearance, Scene, Tool  # noqa: F401
    from .cartesian import CartesianBiDMP, CartesianDMP  # noqa: F401
    from .segmentation import Segmentation, segment  # noqa: F401
    from .similarity import frechet_distance, frechet_similarity  # noqa: F401
    from .io import ModelFileError  # noqa: F401
    from .io import load_model as load  # noqa: F401
    from .io import save_model as save  # noqa: F401


def __getattr__(name: str):
    if name in _LAZY:
        module_name, attribute = _LAZY[name]
        value = getattr(importlib.import_module(module_name), attribute)
    elif name in _SUBMODULES:
        value = importlib.import_module(f"bidmp.{name}")
    else:
        raise AttributeError(f"module 'bidmp' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
