"""Rotations against SciPy's ``Rotation`` (property-based): quaternions and rotation vectors drawn
by hypothesis (any direction and size, near-identity and near-half-turn ones among them). The
oracle for each conversion is SciPy's own composition of the same rotations; for the continuous
logarithm, the closed form of a turn about one axis (the angle grows linearly, whole turns
included); for the readers, SciPy's Euler angles of the numbers written into the file."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from bidmp.io import read_recording
from bidmp.primitives.so3 import (
    angle_between,
    as_quaternions,
    continuous_log,
    orientation_from_log,
    principal_log,
)

FAST = settings(max_examples=150, deadline=None, derandomize=True, database=None)

_COMPONENT = st.one_of(
    st.floats(-1.0, 1.0, allow_nan=False),
    st.sampled_from([0.0, 1e-9, -1e-9, 1.0, -1.0]),
)
QUATERNIONS = st.lists(_COMPONENT, min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 1e-3
)
ROTATION_VECTORS = st.lists(
    st.floats(-3.0 * math.pi, 3.0 * math.pi, allow_nan=False), min_size=3, max_size=3
)


def _same_rotation(q, p, tolerance=1e-9) -> bool:
    """Whether quaternion rows ``q`` and ``p`` are the same rotations (either sign)."""
    return bool(np.all(np.abs(np.sum(_unit(q) * _unit(p), axis=-1)) >= 1.0 - tolerance))


def _unit(q):
    q = np.atleast_2d(np.asarray(q, dtype=float))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


@FAST
@given(st.lists(QUATERNIONS, min_size=1, max_size=5), QUATERNIONS)
def test_principal_log_is_scipys_rotation_vector_of_the_relative_turn(rows, goal):
    q = np.array(rows)
    ours = principal_log(q, np.array(goal))
    relative = Rotation.from_quat(q) * Rotation.from_quat(goal).inv()
    theirs = relative.as_rotvec()
    angles = np.linalg.norm(ours, axis=1)
    assert np.all(angles <= math.pi + 1e-12)
    # the same rotation; the same vector away from a half turn (where the axis' sign is free)
    assert _same_rotation(Rotation.from_rotvec(ours).as_quat(), relative.as_quat())
    away = np.abs(angles - math.pi) > 1e-6
    np.testing.assert_allclose(ours[away], theirs[away], rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        angle_between(q, np.array(goal)), relative.magnitude(), rtol=0, atol=1e-12
    )


@FAST
@given(st.lists(ROTATION_VECTORS, min_size=1, max_size=5), QUATERNIONS)
def test_orientation_from_log_is_scipys_composition(vectors, goal):
    e = np.array(vectors)
    ours = orientation_from_log(e, np.array(goal))
    theirs = (Rotation.from_rotvec(e) * Rotation.from_quat(goal)).as_quat()
    np.testing.assert_allclose(np.linalg.norm(ours, axis=1), 1.0, rtol=0, atol=1e-12)
    assert _same_rotation(ours, theirs)
    # signs continuous: each quaternion on the side of its neighbour
    assert np.all(np.sum(ours[1:] * ours[:-1], axis=1) >= -1e-12)  # (orthogonal: either)


@FAST
@given(
    ROTATION_VECTORS.filter(lambda v: np.linalg.norm(v) > 1e-3),
    st.floats(-4.0 * math.pi, 4.0 * math.pi, allow_nan=False),
    st.integers(20, 120),
    QUATERNIONS,
)
def test_continuous_log_keeps_every_turn_of_a_turn_about_one_axis(axis, total, count, goal):
    """q_k = Exp(s_k A n) ⊗ g with s from -1 to 0: the rotation vectors are s_k A n exactly (up
    to rounding), several turns included; steps of less than a quarter turn."""
    n = np.asarray(axis) / np.linalg.norm(axis)
    s = np.linspace(-1.0, 0.0, count)
    if abs(total) / (count - 1) >= 0.5 * math.pi:
        total = math.copysign(0.49 * math.pi * (count - 1), total)
    wanted = s[:, None] * total * n
    q = (Rotation.from_rotvec(wanted) * Rotation.from_quat(goal)).as_quat()
    np.testing.assert_allclose(continuous_log(q, np.array(goal)), wanted, rtol=0, atol=1e-9)


@FAST
@given(st.lists(QUATERNIONS, min_size=1, max_size=6), st.floats(1e-3, 1e3))
def test_as_quaternions_normalises_and_keeps_the_rotations(rows, scale):
    import warnings

    q = np.array(rows) * scale
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (non-unit rows are normalised with a warning)
        ours = as_quaternions(q)
    np.testing.assert_allclose(np.linalg.norm(ours, axis=1), 1.0, rtol=0, atol=1e-12)
    assert _same_rotation(ours, Rotation.from_quat(q).as_quat())
    assert np.all(np.sum(ours[1:] * ours[:-1], axis=1) >= -1e-12)  # (orthogonal: either)


SEQUENCES = ("xyz", "zyx", "xzy", "ZYX", "XYZ", "ZXZ")


@settings(max_examples=40, deadline=None, derandomize=True, database=None)
@given(
    st.sampled_from(SEQUENCES),
    st.booleans(),
    st.permutations(range(6)),
    st.lists(
        st.lists(st.floats(-170.0, 170.0, allow_nan=False), min_size=3, max_size=3),
        min_size=3,
        max_size=3,
    ),
)
def test_a_recordings_euler_angles_read_as_scipys_rotations(sequence, degrees, order, angles):
    """x, y, z and three Euler angles, in a drawn column order, in degrees or radians, the
    sequence declared: the poses read are SciPy's ``from_euler`` of the numbers written (three
    samples a second apart: any turn between them is one a tool makes)."""
    angles = np.array(angles)
    written = angles if degrees else np.radians(angles)
    names = ["X", "Y", "Z", "A", "B", "C"]
    values = np.column_stack(
        [np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [2.0, 1.0, 0.0]]), written]
    )
    header = ["t", *(names[k] for k in order)]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "pose.csv"
        rows = [
            ",".join([str(second), *(repr(float(row[k])) for k in order)])
            for second, row in enumerate(values)
        ]
        path.write_text(",".join(header) + "\n" + "\n".join(rows) + "\n")
        columns = (
            f"t=t,x=X,y=Y,z=Z,e1=A,e2=B,e3=C,euler={sequence},angles={'deg' if degrees else 'rad'}"
        )
        read = read_recording(path, columns=columns)
    assert read.kind == "pose"
    np.testing.assert_array_equal(read.values[:, :3], values[:, :3])
    theirs = Rotation.from_euler(sequence, written, degrees=degrees).as_quat()
    assert _same_rotation(read.values[:, 3:], theirs, 1e-12)
