"""scikit-learn conventions shared by every estimator: DMP, BLS, BiDMP, GMMRegressor, TPGMM."""

import inspect

import numpy as np
import pytest
from conftest import curved_demo
from sklearn.base import clone

import bidmp
from bidmp import BLS, DMP, BiDMP
from bidmp.baselines import TPGMM, GMMRegressor

ESTIMATORS = [
    (DMP, {"alpha": 40.0, "K": "pastor", "regression": "ridge", "tau": 1.5}),
    (BLS, {"n_windows": 3, "n_enhance": 17, "reg": 1e-3, "seed": 5}),
    (
        BiDMP,
        {
            "dmp": DMP(protocol="paper", alpha=60.0, n_kernels=20),
            "n_enhance": 30,
            "increments": (4, 6),
            "reg": 1e-3,
        },
    ),
    (GMMRegressor, {"n_components": 5, "noise": 0.5, "seed": 3}),
    (TPGMM, {"n_components": 4, "reg_covar": 1e-3, "n_copies": 2}),
]


def fit(model):
    demo = curved_demo(80, 3, seed=7)
    if isinstance(model, BLS):
        return model.fit(demo[:, :2], demo[:, 2])
    return model.fit(demo)


def output(model):
    if isinstance(model, BLS):
        return model.predict(curved_demo(80, 3, seed=7)[:, :2])
    if isinstance(model, (DMP, BiDMP)):
        return model.rollout()
    if isinstance(model, TPGMM):
        return model.rollout(np.ones(3), start=np.zeros(3))
    return model.rollout()


@pytest.mark.parametrize("cls, params", ESTIMATORS, ids=lambda v: getattr(v, "__name__", ""))
def test_parameters_are_stored_under_their_own_names_and_round_trip(cls, params):
    model = cls(**params)
    signature = inspect.signature(cls.__init__).parameters
    for name in signature:
        if name != "self":
            assert getattr(model, name) is model.get_params(deep=False)[name]  # stored as given
    for name, value in params.items():
        assert model.get_params()[name] is value
    assert repr(model).startswith(cls.__name__ + "(")
    copy = clone(model)
    assert type(copy) is cls and copy is not model
    shallow = copy.get_params(deep=False)
    for name, value in model.get_params(deep=False).items():
        if isinstance(value, DMP):
            assert shallow[name].get_params() == value.get_params() and shallow[name] is not value
        else:
            assert shallow[name] == value
    assert model.set_params(**params) is model


@pytest.mark.parametrize("cls, params", ESTIMATORS, ids=lambda v: getattr(v, "__name__", ""))
def test_fitted_state_is_absent_before_fit_and_clone_refits_identically(cls, params):
    model = cls(**params)
    assert not any(name.endswith("_") and not name.startswith("_") for name in vars(model))
    with pytest.raises(bidmp.NotFittedError, match="not fitted"):
        output(model)
    fitted = fit(clone(model))
    again = fit(clone(fitted))  # the clone of a fitted model is unfitted, and refits the same
    np.testing.assert_array_equal(output(again), output(fitted))


@pytest.mark.parametrize("cls, params", ESTIMATORS, ids=lambda v: getattr(v, "__name__", ""))
def test_validation_happens_in_fit_with_the_name_of_the_parameter(cls, params):
    bad = {
        DMP: ("n_kernels", 0),
        BLS: ("n_windows", 0),
        BiDMP: ("n_enhance", 0),
        GMMRegressor: ("n_components", 0),
        TPGMM: ("reg_covar", -1.0),
    }[cls]
    model = cls(**{**params, bad[0]: bad[1]})  # constructing never raises
    with pytest.raises(ValueError, match=bad[0]):
        fit(model)


def test_bidmp_params_include_the_dmps():
    params = BiDMP(DMP(protocol="paper", alpha=60.0, K="paper")).get_params(deep=True)
    assert (
        params["dmp__alpha"] == 60.0
        and params["dmp__K"] == "paper"
        and params["dmp__protocol"] == "paper"
    )
    model = BiDMP(DMP(protocol="paper")).set_params(dmp__alpha=80.0)
    assert model.dmp.alpha_value == 80.0


def test_the_one_thread_limit_holds_the_pools_loaded_after_its_first_use():
    """A first limit before ``import sklearn`` (and SciPy's linear algebra): a later limit still
    holds scikit-learn's OpenMP pool and SciPy's OpenBLAS, and every pool gets its threads back
    on the way out. A fresh interpreter: this one has imported them already."""
    import subprocess
    import sys

    script = (
        "import numpy, sys\n"
        "from bidmp._threads import one_thread, thread_limits\n"
        "assert 'sklearn' not in sys.modules and 'scipy.linalg' not in sys.modules\n"
        "with one_thread():\n"
        "    pass\n"
        "import sklearn.mixture, scipy.linalg\n"
        "from threadpoolctl import threadpool_limits\n"
        "with threadpool_limits(limits=2):\n"
        "    before = thread_limits()\n"
        "    with one_thread():\n"
        "        inside = thread_limits()\n"
        "    after = thread_limits()\n"
        "print(sorted(before.items()), sorted(inside.items()), sorted(after.items()))\n"
        "assert set(inside) == {'blas', 'openmp'} and set(inside.values()) == {1}, inside\n"
        "assert after == before == {'blas': 2, 'openmp': 2}, (before, after)\n"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-2000:]


@pytest.mark.parametrize("cls", [GMMRegressor, TPGMM])
def test_baselines_fit_single_threaded(cls, monkeypatch):
    """EM runs with one BLAS / OpenMP thread: on 2 cores the pools made it 7-15x slower."""
    from sklearn.mixture import GaussianMixture

    from bidmp._threads import thread_limits

    seen = []
    original = GaussianMixture.fit

    def spy(self, *args, **kwargs):
        seen.append(thread_limits())
        return original(self, *args, **kwargs)

    monkeypatch.setattr(GaussianMixture, "fit", spy)
    fit(cls(n_components=3, n_copies=1))
    assert seen and all(limit == 1 for limit in seen[0].values()), seen
