"""A BLS's state for model files (``bidmp.io`` stores it): what is written, and every member
checked on the way back in."""

from __future__ import annotations

import numpy as np

from .._checks import (
    check_fitted,
    check_int,
    check_limit,
    check_loaded,
)


# -- persistence -----------------------------------------------------------------------------
def _bls_state(model, y_was_1d: bool) -> tuple[dict, dict]:
    """A fitted BLS's model-file form; ``y_was_1d``: it was fitted on a 1-D target (its
    predictions are then 1-D too)."""
    check_fitted(model, "output_weights_")
    arrays = {
        "mapping_weights_": model.mapping_weights_,
        "mapping_min_": model.mapping_min_,
        "mapping_range_": model.mapping_range_,
        "enhancement_scales_": np.asarray(model.enhancement_scales_),
        "output_weights_": model.output_weights_,
        "train_hidden_": np.ascontiguousarray(model.train_hidden_),
        "train_targets_": model.train_targets_,
    }
    for block, weights in enumerate(model.enhancement_weights_):
        arrays[f"enhancement_weights_{block}"] = weights
    arrays["pinv_or_gram"] = (
        model.hidden_pinv_ if model.update_rule_ == "pinv" else model.gram_factor_
    )
    meta = {
        "params": model.get_params(),
        "n_features_": model.n_features_,
        "n_blocks": len(model.enhancement_weights_),
        "y_was_1d": bool(y_was_1d),
    }
    return meta, arrays


def _bls_params(meta: dict) -> dict:
    """A model file's BLS parameters (checked by the BLS they make)."""
    if not isinstance(meta.get("params"), dict):
        raise ValueError("the BLS state has no params object")
    return meta["params"]


def _bls_members(meta: dict, arrays, params) -> dict:
    """A model file's fitted BLS, every member checked against the resolved ``params``
    (``_BLSParams``) and the others: the fitted attributes by name, and ``y_was_1d`` and
    ``train_hidden`` (the training inputs' hidden matrix)."""
    out = {}
    n_features = check_int(meta["n_features_"], "n_features_", minimum=1, limit="max_hidden_nodes")
    n_blocks = check_int(meta["n_blocks"], "n_blocks", minimum=1, limit="max_hidden_nodes")
    if not isinstance(meta["y_was_1d"], bool):
        raise ValueError("y_was_1d must be true or false")
    out["n_features_"], out["y_was_1d"] = n_features, meta["y_was_1d"]
    n_mapped = params.n_windows * params.n_mapped
    out["mapping_weights_"] = check_loaded(
        arrays["mapping_weights_"],
        "mapping_weights_",
        (params.n_windows, n_features + 1, params.n_mapped),
    )
    out["mapping_min_"] = check_loaded(arrays["mapping_min_"], "mapping_min_", (n_mapped,))
    out["mapping_range_"] = check_loaded(
        arrays["mapping_range_"], "mapping_range_", (n_mapped,), positive=True
    )
    enhancement = [
        check_loaded(
            arrays[f"enhancement_weights_{b}"], f"enhancement_weights_{b}", (n_mapped + 1, None)
        )
        for b in range(n_blocks)
    ]
    out["enhancement_weights_"] = enhancement
    scales = check_loaded(
        arrays["enhancement_scales_"], "enhancement_scales_", (n_blocks,), positive=True
    )
    out["enhancement_scales_"] = [float(v) for v in scales]
    n_hidden = n_mapped + sum(w.shape[1] for w in enhancement)
    check_limit(n_hidden, "max_hidden_nodes", "the model's hidden nodes")
    output = check_loaded(arrays["output_weights_"], "output_weights_", (n_hidden, None))
    out["output_weights_"] = output
    n_outputs = output.shape[1]
    if out["y_was_1d"] and n_outputs != 1:
        raise ValueError("member output_weights_ must have one column for a 1-D target")
    train_hidden = check_loaded(arrays["train_hidden_"], "train_hidden_", (None, n_hidden))
    n_samples = train_hidden.shape[0]
    out["train_hidden"] = train_hidden
    out["train_targets_"] = check_loaded(
        arrays["train_targets_"], "train_targets_", (n_samples, n_outputs)
    )
    if params.update == "pinv":
        companion = check_loaded(arrays["pinv_or_gram"], "pinv_or_gram", (n_hidden, n_samples))
        out["hidden_pinv_"], out["gram_factor_"] = companion, None
    else:
        companion = check_loaded(arrays["pinv_or_gram"], "pinv_or_gram", (n_hidden, n_hidden))
        if not np.all(np.diag(companion) > 0) or np.any(np.tril(companion, -1) != 0):
            raise ValueError(
                "member pinv_or_gram is not an upper Cholesky factor (positive diagonal, zero below)"
            )
        out["hidden_pinv_"], out["gram_factor_"] = None, np.asfortranarray(companion)
    return out
