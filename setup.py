"""The compiled part of bidmp (everything else is in pyproject.toml): the robot fit's searches."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension(
            "bidmp.primitives._kernels",
            ["src/bidmp/primitives/_kernels.pyx"],
            # No fused multiply-adds: the loops' decisions are checked against NumPy's arithmetic.
            extra_compile_args=["-O2", "-ffp-contract=off"],
        )
    ]
)
