"""A DMP's state for model files (``bidmp.io`` stores it as ``.npz`` + JSON): what is written, and
how a file's members are checked on the way back in, for every model format since 1."""

from __future__ import annotations

import dataclasses

import numpy as np

from .._checks import (
    as_unit_quaternion,
    check_int,
    check_loaded,
    check_names,
    check_real,
    get_limits,
)
from .._units import check_units
from .canonical import ExponentialPhase
from .forcing import GaussianBasis
from .integrate import _check_euler_stable

__all__ = []


def _dmp_state(model) -> tuple[dict, dict]:
    """A fitted DMP's state for a model file: (JSON-able meta, arrays); the caller has checked
    that it is fitted."""
    arrays = {
        "weights_": model.weights_,
        "start_": model.start_,
        "goal_": model.goal_,
        "centres_": model.centres_,
        "widths_": model.widths_,
    }
    if model.__dict__.get("goal_gate_") is not None:
        arrays["goal_gate_"] = model.goal_gate_
    if model.__dict__.get("held_orientation_") is not None:
        arrays["held_orientation_"] = model.held_orientation_
    meta = {
        "params": _params_state(model.get_params()),
        "n_steps_": model.n_steps_,
        "duration_": model.duration_,
        "units_": model.units_,
    }
    if model.__dict__.get("names_"):
        meta["names_"] = list(model.names_)
    return meta, arrays


# The components a model file can name: the classes bidmp ships (a file never names code to run).
_COMPONENTS = {"ExponentialPhase": ExponentialPhase, "GaussianBasis": GaussianBasis}


def _params_state(params: dict) -> dict:
    """A DMP's parameters for JSON: a component given (canonical system, basis) as its class's
    name and fields; unset components are left out (files written before components read the same)."""
    state = {}
    for name, value in params.items():
        if name in ("canonical_system", "forcing_basis"):
            if value is None:
                continue
            kind = type(value).__name__
            if _COMPONENTS.get(kind) is not type(value):
                raise ValueError(
                    f"a model file can hold bidmp's own components ({', '.join(_COMPONENTS)}); "
                    f"this DMP's {name} is a {kind}"
                )
            settings = {f.name: getattr(value, f.name) for f in dataclasses.fields(value) if f.init}
            value = {"type": kind, **settings}
        state[name] = value
    return state


def _component_from_state(value, name: str):
    """A component from its model-file form ``{"type": ..., fields}``, checked."""
    if not isinstance(value, dict) or value.get("type") not in _COMPONENTS:
        raise ValueError(
            f"member params.{name} must name one of {', '.join(_COMPONENTS)} with its fields"
        )
    fields = {key: item for key, item in value.items() if key != "type"}
    try:
        return _COMPONENTS[value["type"]](**fields)
    except TypeError as error:
        raise ValueError(f"member params.{name}: {error}") from None


def _dmp_from_state(cls, meta: dict, arrays) -> object:
    """A DMP of class ``cls`` from a model file's state, every member checked (a corrupt or forged
    file raises ``ValueError`` naming the member)."""
    params = dict(meta["params"])
    for name in ("canonical_system", "forcing_basis"):
        if params.get(name) is not None:
            params[name] = _component_from_state(params[name], name)
    if "fit" in params:  # format 1 stored the regression under the name "fit"
        params["regression"] = params.pop("fit")
    params.setdefault("protocol", "paper")  # formats 1-2 knew only the paper's protocol
    if "integrator" not in params:  # formats 1-3 integrated with explicit Euler
        params["integrator"] = "euler"
    model = cls(**params)
    params = model.settings()
    n_kernels = params.n_kernels
    n_steps = check_int(meta["n_steps_"], "n_steps_", minimum=3, limit="max_samples")
    weights = check_loaded(arrays["weights_"], "weights_", (n_kernels, None))
    n_dims = weights.shape[1]
    check_int(n_dims, "the model's number of dimensions D", minimum=1, limit="max_dims")
    model.weights_ = weights
    model.start_ = check_loaded(arrays["start_"], "start_", (n_dims,))
    model.goal_ = check_loaded(arrays["goal_"], "goal_", (n_dims,))
    model.centres_ = check_loaded(arrays["centres_"], "centres_", (n_kernels,), positive=True)
    model.widths_ = check_loaded(arrays["widths_"], "widths_", (n_kernels,), positive=True)
    for name in ("weights_", "start_", "goal_"):
        limit = (
            1e3 * get_limits().max_abs_value if name == "weights_" else get_limits().max_abs_value
        )
        if np.max(np.abs(getattr(model, name))) > limit:
            raise ValueError(f"member {name} has values beyond {limit:.3g}, which no fit produces")
    if np.any(model.centres_ > 1.0):
        raise ValueError("member centres_ must lie in (0, 1] (they are phases)")
    model.n_steps_ = n_steps
    model.dt_ = 1.0 / n_steps
    model.duration_ = check_real(
        meta.get("duration_", (n_steps - 1) / n_steps), "duration_", positive=True, maximum=1e7
    )
    if (n_steps - 1) / model.duration_ > 1e5 or (n_steps - 1) / model.duration_ < 1e-3:
        raise ValueError(
            f"duration_ = {model.duration_:g} s implies an implausible sample rate for {n_steps} samples"
        )
    model.units_ = check_units(meta.get("units_", ""))
    # absent before bidmp 0.6: unnamed
    model.names_ = check_names(meta.get("names_"), n_dims, "names_")
    model.held_orientation_ = (
        as_unit_quaternion(
            check_loaded(arrays["held_orientation_"], "held_orientation_", (4,)),
            "member held_orientation_",
        )
        if "held_orientation_" in arrays
        else None
    )
    model.goal_gate_ = None
    if params.goal_rate is None:
        gate = check_loaded(arrays["goal_gate_"], "goal_gate_", (model.n_train_,))
        if np.max(np.abs(gate)) > 1e6:
            raise ValueError("member goal_gate_ has values beyond 1e6, which no fit produces")
        model.goal_gate_ = gate
    if params.integrator == "euler":
        _check_euler_stable(model.dt_, 1.0, params.alpha, params.beta)
    return model
