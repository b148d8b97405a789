"""A BLS's state for model files (``bidmp.io`` stores it): what is written, and every member
checked on the way back in."""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_triangular

from .._checks import (
    check_fitted,
    check_int,
    check_limit,
    check_loaded,
)


# -- persistence -----------------------------------------------------------------------------
def _bls_state(model) -> tuple[dict, dict]:
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
        "y_was_1d": bool(model._y_was_1d),
    }
    return meta, arrays


def _bls_from_state(cls, meta: dict, arrays: dict):
    if not isinstance(meta.get("params"), dict):
        raise ValueError("the BLS state has no params object")
    model = cls(**meta["params"])
    params = model._params()
    model.n_features_ = check_int(
        meta["n_features_"], "n_features_", minimum=1, limit="max_hidden_nodes"
    )
    n_blocks = check_int(meta["n_blocks"], "n_blocks", minimum=1, limit="max_hidden_nodes")
    if not isinstance(meta["y_was_1d"], bool):
        raise ValueError("y_was_1d must be true or false")
    model._y_was_1d = meta["y_was_1d"]
    n_mapped = params.n_windows * params.n_mapped
    model.mapping_weights_ = check_loaded(
        arrays["mapping_weights_"],
        "mapping_weights_",
        (params.n_windows, model.n_features_ + 1, params.n_mapped),
    )
    model.mapping_min_ = check_loaded(arrays["mapping_min_"], "mapping_min_", (n_mapped,))
    model.mapping_range_ = check_loaded(
        arrays["mapping_range_"], "mapping_range_", (n_mapped,), positive=True
    )
    model.enhancement_weights_ = [
        check_loaded(
            arrays[f"enhancement_weights_{b}"], f"enhancement_weights_{b}", (n_mapped + 1, None)
        )
        for b in range(n_blocks)
    ]
    scales = check_loaded(
        arrays["enhancement_scales_"], "enhancement_scales_", (n_blocks,), positive=True
    )
    model.enhancement_scales_ = [float(v) for v in scales]
    n_hidden = n_mapped + sum(w.shape[1] for w in model.enhancement_weights_)
    check_limit(n_hidden, "max_hidden_nodes", "the model's hidden nodes")
    model.output_weights_ = check_loaded(
        arrays["output_weights_"], "output_weights_", (n_hidden, None)
    )
    n_outputs = model.output_weights_.shape[1]
    if model._y_was_1d and n_outputs != 1:
        raise ValueError("member output_weights_ must have one column for a 1-D target")
    train_hidden = check_loaded(arrays["train_hidden_"], "train_hidden_", (None, n_hidden))
    n_samples = train_hidden.shape[0]
    model.train_targets_ = check_loaded(
        arrays["train_targets_"], "train_targets_", (n_samples, n_outputs)
    )
    model._set_train_hidden(train_hidden)
    if params.update == "pinv":
        companion = check_loaded(arrays["pinv_or_gram"], "pinv_or_gram", (n_hidden, n_samples))
        model.hidden_pinv_, model.gram_factor_, model._projected_targets = companion, None, None
    else:
        companion = check_loaded(arrays["pinv_or_gram"], "pinv_or_gram", (n_hidden, n_hidden))
        if not np.all(np.diag(companion) > 0) or np.any(np.tril(companion, -1) != 0):
            raise ValueError(
                "member pinv_or_gram is not an upper Cholesky factor (positive diagonal, zero below)"
            )
        model.hidden_pinv_, model.gram_factor_ = None, np.asfortranarray(companion)
        model._projected_targets = solve_triangular(
            model.gram_factor_, model.train_hidden_.T @ model.train_targets_, trans="T"
        )
    return model
