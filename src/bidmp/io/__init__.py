"""Files: trajectory and pose files (CSV/NPY), model files (``.npz`` + JSON metadata, never
pickles), strict JSON, and atomic writes (temporary file, then rename).

* ``trajectories``, ``poses`` — read and write recordings and generated motions;
* ``models`` — :func:`save_model` / :func:`load_model` for every model class, every format since 1;
* ``strict_json`` — JSON with size and depth caps, no NaN;
* ``atomic`` — :func:`atomic_write`.

**Reads** never trust a file: sizes are checked from the headers before anything is allocated
(:class:`bidmp.Limits`). Layer 2 (data): imports the math only to build the objects it reads;
never ``tasks``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "ModelFileError": "models",
    "FORMAT_VERSION": "models",
    "save_model": "models",
    "load_model": "models",
    "load_trajectory": "trajectories",
    "read_trajectory": "trajectories",
    "save_trajectory": "trajectories",
    "declared_units": "trajectories",
    "is_joint_recording": "recordings",
    "read_poses": "poses",
    "save_poses": "poses",
    "atomic_write": "atomic",
    "load_json": "strict_json",
    "json_number": "strict_json",
    "Recording": "recordings",
    "read_recording": "recordings",
    "recording_kind": "recordings",
    "read_bag": "bags",
    "write_bag": "bags",
    "is_bag": "bags",
    "start_stamp": "bags",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
