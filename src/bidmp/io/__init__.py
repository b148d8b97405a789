"""Files: trajectory and pose files (CSV/NPY), model files (``.npz`` + JSON metadata, never
pickles), strict JSON, and atomic writes (temporary file, then rename).

* ``trajectories``, ``poses`` — read and write recordings and generated motions;
* ``models`` — :func:`save_model` / :func:`load_model` for every model class, every format since 1;
* ``strict_json`` — JSON with size and depth caps, no NaN;
* ``atomic`` — :func:`atomic_write`;
* ``runs`` — :func:`run_folder`: a command's output folder written as one run (a new folder
  swapped in whole, a ``manifest.json`` of its files' SHA-256), :func:`check_run_files`.

**Reads** never trust a file: sizes are checked from the headers before anything is allocated
(:class:`bidmp.Limits`). Layer 2 (data): imports the math only to build the objects it reads;
never ``tasks``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .atomic import atomic_write
    from .bags import is_bag, read_bag, start_stamp, write_bag
    from .models import FORMAT_VERSION, ModelFileError, load_model, save_model
    from .poses import read_poses, save_poses
    from .recordings import Recording, is_joint_recording, read_recording, recording_kind
    from .runs import (
        MANIFEST,
        OutputFiles,
        RunFolder,
        RunManifest,
        check_run_files,
        output_files,
        read_manifest,
        run_folder,
        update_manifest,
    )
    from .strict_json import json_number, load_json
    from .trajectories import declared_units, load_trajectory, read_trajectory, save_trajectory
__getattr__, __dir__ = exports(__name__, __file__, globals())
