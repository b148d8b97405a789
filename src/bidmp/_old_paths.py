"""The flat module paths of bidmp ≤ 0.4 (``bidmp.dmp``, ``bidmp.geometry``, …), kept importable.

bidmp 0.5 moved its modules into subpackages (``bidmp.primitives``, ``bidmp.scene``, …, see the
README's developer notes). Code written against the old paths keeps working: ``import
bidmp.dmp`` gives a module that looks names up, in order, in the modules that now hold what the
old one held. This is one table in one place rather than a shim file per old module, so the tree
shows only the new layout. New code should import from the subpackages.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types

# old module path -> the new modules that hold its names, searched in order
OLD_PATHS: dict[str, tuple[str, ...]] = {
    "bidmp.dmp": ("bidmp.primitives.dmp", "bidmp.primitives.canonical", "bidmp.primitives.forcing",
                  "bidmp.primitives.integrate", "bidmp.primitives.stepper", "bidmp.primitives.protocols",
                  "bidmp.primitives.goals"),
    "bidmp.timing": ("bidmp.primitives.timing", "bidmp.demonstrations.prepare"),
    "bidmp.cartesian": ("bidmp.primitives.cartesian", "bidmp.incremental.cartesian", "bidmp.demonstrations.prepare",
                        "bidmp.primitives.so3", "bidmp.primitives.pose_timing"),
    "bidmp.datasets": ("bidmp.demonstrations.datasets",),
    "bidmp.segmentation": ("bidmp.extension.segmentation",),
    "bidmp.similarity": ("bidmp.extension.similarity",),
    "bidmp.roadmap": ("bidmp.extension.roadmap",),
    "bidmp.bls": ("bidmp.incremental.bls",),
    "bidmp.geometry": ("bidmp.scene.parts", "bidmp.scene.clearance", "bidmp.scene.checker", "bidmp.scene.distances"),
    "bidmp.scenarios": ("bidmp.tasks.scenarios",),
    "bidmp.evaluation": ("bidmp.tasks.evaluation",),
    "bidmp.metrics": ("bidmp.tasks.metrics",),
    "bidmp.reproduce": ("bidmp.experiments.reproduce", "bidmp.experiments.table4", "bidmp.experiments.table5",
                        "bidmp.experiments.incremental", "bidmp.experiments.generalisation"),
    "bidmp.benchmark": ("bidmp.experiments.lasa",),
}


def _old_module(name: str, sources: tuple[str, ...]) -> types.ModuleType:
    modules = [importlib.import_module(source) for source in sources]
    module = types.ModuleType(name, f"Old path of {', '.join(sources)} (see bidmp._old_paths).")

    def __getattr__(attribute: str):
        for source in modules:
            if hasattr(source, attribute):
                return getattr(source, attribute)
        raise AttributeError(f"module {name!r} has no attribute {attribute!r}")

    module.__getattr__ = __getattr__
    module.__all__ = [n for source in modules for n in getattr(source, "__all__", ())]
    module.__dir__ = lambda: sorted(set(module.__all__))
    return module


class _OldPathLoader(importlib.abc.Loader):
    def create_module(self, spec):
        return _old_module(spec.name, OLD_PATHS[spec.name])

    def exec_module(self, module) -> None:
        pass


class _OldPathFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname not in OLD_PATHS:
            return None
        return importlib.machinery.ModuleSpec(fullname, _OldPathLoader())


def install() -> None:
    """Make the old paths importable (idempotent; called by ``bidmp/__init__``)."""
    if not any(isinstance(finder, _OldPathFinder) for finder in sys.meta_path):
        sys.meta_path.append(_OldPathFinder())
