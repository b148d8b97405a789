"""The compiled part of bidmp (everything else is in pyproject.toml): the inner loops of the DMP's
fit and rollout and of pose arithmetic (src/bidmp/_kernels.pyx)."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "bidmp._kernels",
            ["src/bidmp/_kernels.pyx"],
            # No fused multiply-adds: the loops give the bits of the NumPy and SciPy arithmetic
            # they replaced (the tests compare them to the bit).
            extra_compile_args=["-O2", "-ffp-contract=off"],
        )
    ]
)
