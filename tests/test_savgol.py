"""``bidmp._savgol.savgol_filter`` against SciPy's own ``scipy.signal.savgol_filter``, to the last
bit, on signals, windows, orders, derivatives, spacings and axes drawn at random (the library's
calls use a few of them; these go beyond). It replaces SciPy's function only to spare a command the
import of ``scipy.signal``, so its numbers must be SciPy's: this is a check against an independent
reference, and it fails first if an upgrade of SciPy changes its arithmetic."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_filter as scipy_savgol_filter

from bidmp._savgol import savgol_filter


def _bits(array) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float64).view(np.int64)


def _signal(rng, shape) -> np.ndarray:
    """A smooth signal with noise at a random scale and offset."""
    grid = np.linspace(0.0, 1.0, shape[0]).reshape((-1,) + (1,) * (len(shape) - 1))
    signal = np.sin(grid * rng.uniform(1, 9) + rng.uniform(0, 6, shape[1:]))
    signal = signal + rng.normal(scale=10 ** rng.uniform(-6, -1), size=shape)
    return signal * 10 ** rng.uniform(-3, 3) + rng.uniform(-1e3, 1e3)


def test_savgol_is_scipys_to_the_bit():
    rng = np.random.default_rng(21)
    for trial in range(400):
        n_dims = int(rng.integers(1, 4))
        length = int(rng.integers(3, 200))
        shape = [length] + [int(rng.integers(1, 5)) for _ in range(n_dims - 1)]
        axis_index = int(rng.integers(0, n_dims))
        shape[0], shape[axis_index] = shape[axis_index], shape[0]
        x = _signal(rng, (shape[axis_index], *shape[:axis_index], *shape[axis_index + 1 :]))
        x = np.moveaxis(x, 0, axis_index)
        axis = axis_index - n_dims if rng.random() < 0.5 else axis_index
        window = int(rng.integers(2, min(length, 41) + 1))
        polyorder = int(rng.integers(0, min(window - 1, 5) + 1))
        deriv = int(rng.integers(0, polyorder + 2))  # one past the order: all zero coefficients
        delta = float(10 ** rng.uniform(-4, 1)) if rng.random() < 0.7 else 1.0
        expected = scipy_savgol_filter(x, window, polyorder, deriv=deriv, delta=delta, axis=axis)
        out = savgol_filter(x, window, polyorder, deriv=deriv, delta=delta, axis=axis)
        assert out.shape == expected.shape, trial
        assert np.array_equal(_bits(out), _bits(expected)), (trial, window, polyorder, deriv, axis)


def test_savgol_hands_other_modes_and_bad_arguments_to_scipy():
    rng = np.random.default_rng(22)
    x = _signal(rng, (50, 2))
    for mode in ("mirror", "nearest", "constant", "wrap"):
        expected = scipy_savgol_filter(x, 7, 2, axis=0, mode=mode)
        assert np.array_equal(_bits(savgol_filter(x, 7, 2, axis=0, mode=mode)), _bits(expected))
    integers = np.arange(30) ** 2
    assert np.array_equal(
        _bits(savgol_filter(integers, 5, 2)), _bits(scipy_savgol_filter(integers, 5, 2))
    )
    with pytest.raises(ValueError, match="polyorder must be less than window_length"):
        savgol_filter(x, 5, 5, axis=0)
    with pytest.raises(ValueError, match="window_length must be less"):
        savgol_filter(x, 51, 2, axis=0)
    with pytest.raises(Exception) as ours:
        savgol_filter(x, 5, 2, axis=2)
    with pytest.raises(Exception) as scipys:
        scipy_savgol_filter(x, 5, 2, axis=2)
    assert type(ours.value) is type(scipys.value)


def test_smoothing_a_path_does_not_import_scipy_signal(loaded_after):
    """What the module is for: the extension's smoothing runs without ``scipy.signal``."""
    code = (
        "import numpy as np\n"
        "from bidmp._trajectory import savgol_filter\n"
        "y = np.cumsum(np.random.default_rng(0).normal(size=(200, 3)), axis=0)\n"
        "savgol_filter(y, 11, 3, axis=0); savgol_filter(y, 11, 3, deriv=2, delta=0.01, axis=0)"
    )
    assert loaded_after(code, ("scipy.signal",)) == []
