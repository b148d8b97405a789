"""Single-threaded BLAS and OpenMP for small dense algebra (the BLS, the baselines' EM).

NumPy and SciPy each load their own OpenBLAS, each with a thread pool, and scikit-learn adds an
OpenMP pool. When calls alternate between them (``@`` here, ``scipy.linalg`` there), the idle
pools' threads spin and steal the cores from the busy one: on a 2-core machine a BLS node
addition took 24 ms instead of 4 ms, and a review measured ``GaussianMixture`` at 3–7.5 s instead
of 0.35–0.5 s (``benchmarks/bench_scenario.py`` prints the ratio on the machine at hand).
Matrices of a few hundred columns gain nothing from threads, so these hot paths run with one
thread, scoped (the caller's settings are restored; nothing global changes).
"""

from __future__ import annotations

import functools

_controller = None


def thread_limits() -> dict[str, int]:
    """The current thread count of every loaded pool, by user API (``"blas"``, ``"openmp"``)."""
    from threadpoolctl import threadpool_info

    limits: dict[str, int] = {}
    for pool in threadpool_info():
        limits[pool["user_api"]] = max(limits.get(pool["user_api"], 0), pool["num_threads"])
    return limits


def one_thread():
    """Context manager: every loaded BLAS and OpenMP pool limited to one thread inside it."""
    global _controller
    if _controller is None:
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()  # inspects the loaded libraries once (~7 ms)
    return _controller.limit(limits=1)


def single_threaded(function):
    """Decorator: run ``function`` with every loaded BLAS and OpenMP pool limited to one thread."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with one_thread():
            return function(*args, **kwargs)

    return wrapper
