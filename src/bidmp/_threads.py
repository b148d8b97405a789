"""Single-threaded BLAS for the small dense algebra of the Broad Learning System.

NumPy and SciPy each load their own OpenBLAS, each with a thread pool. When calls alternate
between the two (``@`` here, ``scipy.linalg`` there), the idle pool's threads spin and steal the
cores from the busy one: on a 2-core machine a BLS node addition took 24 ms instead of 4 ms.
Matrices of a few hundred columns gain nothing from BLAS threads, so the BLS hot paths run with
one thread, scoped (the caller's settings are restored; nothing global changes).
"""

from __future__ import annotations

import functools

_controller = None


def single_threaded_blas(function):
    """Decorator: run ``function`` with every loaded BLAS limited to one thread."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        global _controller
        if _controller is None:
            from threadpoolctl import ThreadpoolController

            _controller = ThreadpoolController()  # inspects the loaded libraries once (~7 ms)
        with _controller.limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return wrapper
