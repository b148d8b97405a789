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
import sys

# The modules whose import loads a thread pool beside NumPy's OpenBLAS: SciPy's own OpenBLAS
# (scipy.linalg), scikit-learn's OpenMP, torch's. The pools are found again when one of them
# has been imported since the last look: a controller holds only the libraries loaded when it
# was made, so one made before ``import sklearn`` would leave scikit-learn's OpenMP pool free.
_POOL_MODULES = ("scipy.linalg", "sklearn.utils._openmp_helpers", "torch")
_pools: tuple = ((), ())  # (which of _POOL_MODULES were loaded, the library controllers)


def _library_controllers() -> tuple:
    global _pools
    loaded = tuple(name in sys.modules for name in _POOL_MODULES)
    if loaded != _pools[0]:
        from threadpoolctl import ThreadpoolController

        # inspecting the loaded libraries takes ~7 ms: once per new pool, not per call
        _pools = (loaded, tuple(ThreadpoolController().lib_controllers))
    return _pools[1]


class _OneThread:
    """Every loaded pool at one thread inside, each restored on the way out. threadpoolctl's own
    ``limit`` does the same, plus a full report of every library (versions, architectures) on
    each entry: 0.12 ms a call once other work has cooled the caches (a fit beside another
    library's run), against 0.08 ms for this."""

    __slots__ = ("_restore",)

    def __enter__(self):
        restore = []
        for library in _library_controllers():
            threads = library.get_num_threads()
            if threads != 1:
                library.set_num_threads(1)
                restore.append((library, threads))
        self._restore = restore
        return self

    def __exit__(self, *exc_info) -> None:
        for library, threads in reversed(self._restore):
            library.set_num_threads(threads)


def thread_limits() -> dict[str, int]:
    """The current thread count of every loaded pool, by user API (``"blas"``, ``"openmp"``)."""
    from threadpoolctl import threadpool_info

    limits: dict[str, int] = {}
    for pool in threadpool_info():
        limits[pool["user_api"]] = max(limits.get(pool["user_api"], 0), pool["num_threads"])
    return limits


def one_thread() -> _OneThread:
    """Context manager: every loaded BLAS and OpenMP pool limited to one thread inside it (the
    pools loaded by then, ``import sklearn`` after the first call included)."""
    return _OneThread()


def single_threaded(function):
    """Decorator: run ``function`` with every loaded BLAS and OpenMP pool limited to one thread."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with one_thread():
            return function(*args, **kwargs)

    return wrapper
