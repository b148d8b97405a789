"""Files: trajectory and pose CSV/NPY files, model files (``.npz`` + JSON metadata, never pickles),
strict JSON, and atomic writes (temporary file, then rename).

Layer 2 (data): imports the math only to build the objects it reads; never ``tasks``, ``sim`` or
``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "ModelFileError": "files",
    "FORMAT_VERSION": "files",
    "save_model": "files",
    "load_model": "files",
    "load_trajectory": "files",
    "read_trajectory": "files",
    "read_poses": "files",
    "save_poses": "files",
    "save_trajectory": "files",
    "atomic_write": "files",
    "load_json": "files",
}
__all__ = list(_EXPORTS)
# what the flat module bidmp.io of bidmp <= 0.4 held, for code written against it
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals(), fallback=("files",))
