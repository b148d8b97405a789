"""A Bi-DMP's state for model files (``bidmp.io`` stores it): its DMP, skills and BLS blocks, every
member checked on the way back in (formats 2 and later)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .._checks import (
    _check_magnitude,
    check_loaded,
    check_real,
)
from .._state import Prefixed as _Prefixed
from ..primitives.dmp import DMP
from .bls import BLS


# -- persistence -----------------------------------------------------------------------------
def _bidmp_state(model) -> tuple[dict, dict]:
    """A started Bi-DMP's model-file form: its DMP's and blocks' under their prefixes, its skills'
    goals, starts and time scales, its parameters but the DMP."""
    dmp_meta, dmp_arrays = model.dmp_.to_state()
    arrays = {f"dmp/{k}": v for k, v in dmp_arrays.items()}
    arrays["skill_goals_"] = model.skill_goals_
    arrays["skill_starts_"] = model.skill_starts_
    arrays["skill_time_scales_"] = model.skill_time_scales_
    blocks_meta = []
    for index, block in enumerate(model.blocks_):
        meta, block_arrays = block.to_state()
        blocks_meta.append(meta)
        arrays.update({f"block{index}/{k}": v for k, v in block_arrays.items()})
    params = {k: v for k, v in model.get_params(deep=False).items() if k != "dmp"}
    params["increments"] = list(model.increments)
    return {
        "params": params,
        "dmp": dmp_meta,
        "blocks": blocks_meta,
        "phase_min_": model.phase_min_,
        "gate_phase_": model.gate_phase_,
    }, arrays


def _bidmp_parts(meta: dict, arrays: Mapping) -> tuple:
    """A model file's Bi-DMP before its skills: its fitted DMP (read from its prefix, every member
    checked) and its other parameters, ``(dmp, params)``."""
    for key, kind in (("dmp", dict), ("params", dict), ("blocks", list)):
        if not isinstance(meta.get(key), kind):
            raise ValueError(f"the Bi-DMP state has no {key} {kind.__name__}")
    dmp = DMP.from_state(meta["dmp"], _Prefixed(arrays, "dmp/"))
    params = dict(meta["params"])
    if not isinstance(params.get("increments"), list):
        raise ValueError("params.increments must be a list of integers")
    params["increments"] = tuple(params["increments"])
    return dmp, params


def _restore_skills(model, meta: dict, arrays: Mapping) -> None:
    """A started Bi-DMP's learned skills from a model file's state: its BLS blocks (read from
    their prefixes), the skills' goals, starts and time scales, every member checked against the
    DMP the model runs."""
    dmp = model.dmp_
    model.phase_min_ = check_real(meta["phase_min_"], "phase_min_", positive=True, maximum=1.0)
    model.gate_phase_ = check_real(
        meta.get("gate_phase_", 1.0), "gate_phase_", positive=True, maximum=1.0
    )
    model.blocks_ = [
        BLS.from_state(block_meta, _Prefixed(arrays, f"block{index}/"))
        for index, block_meta in enumerate(meta["blocks"])
    ]
    for index, block in enumerate(model.blocks_):
        if (
            block.n_features_ != dmp.weights_.shape[0]
            or block.output_weights_.shape[1] != dmp.n_dims_
        ):
            raise ValueError(
                f"block {index} maps {block.n_features_} inputs to {block.output_weights_.shape[1]} outputs; "
                f"the DMP has {dmp.weights_.shape[0]} kernels and D = {dmp.n_dims_}"
            )
    expected = (len(model.blocks_) + 1, dmp.n_dims_)
    model.skill_goals_ = check_loaded(arrays["skill_goals_"], "skill_goals_", expected)
    model.skill_starts_ = check_loaded(arrays["skill_starts_"], "skill_starts_", expected)
    for name in ("skill_goals_", "skill_starts_"):
        _check_magnitude(getattr(model, name), f"member {name}")
    if "skill_time_scales_" in arrays:
        model.skill_time_scales_ = check_loaded(
            arrays["skill_time_scales_"], "skill_time_scales_", (expected[0],), positive=True
        )
        if (
            model.skill_time_scales_[0] != 1.0
            or np.any(model.skill_time_scales_ > 1e3)
            or np.any(model.skill_time_scales_ < 1e-3)
        ):
            raise ValueError(
                "member skill_time_scales_ must be 1 for skill 0 and within [0.001, 1000]"
            )
    else:  # formats 2-4: every skill took the demonstration's time
        model.skill_time_scales_ = np.ones(expected[0])
