"""One joint motion, every reader (property-based): the motion drawn by hypothesis (2-6 joints of
drawn names, 3-25 samples of drawn positions, tiny and subnormal ones among them, stamps 1-50 ms
apart far from zero) is written as a CSV (``t,<names>``), a ROS 1 bag, a ROS 2 MCAP bag and a ROS 2
SQLite bag with the joints in a drawn order in every message (each message its own), and an
``.npy`` array; each reads back the drawn numbers exactly. The oracle is the drawn motion itself,
written by rosbags' own writers and typestores (not bidmp's) and by hand."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rosbags.typesys import Stores, get_typestore

from bidmp import get_limits
from bidmp.io import read_bag, read_recording

# the CSV reader's reserved names (time, positions, quaternions), and what it reads beside them
_RESERVED = {"time", "stamp", "timestamp"}
_VALUES = st.one_of(
    st.floats(-3.0, 3.0, allow_nan=False, allow_infinity=False),
    st.sampled_from([0.0, 1e-300, -1e-300, 5e-324, 2.2250738585072014e-308]),
)


@st.composite
def joint_motions(draw):
    """(names, stamps ns (n,), positions (n, J), orders: each message's joint order (n, J))."""
    names = draw(
        st.lists(
            st.text(alphabet="abcdefghijklmnopsuw", min_size=2, max_size=8),
            min_size=2,
            max_size=6,
            unique=True,
        ).filter(
            lambda found: (
                not _RESERVED & set(found)
                # t, <names>, v<names>, a<names> is bidmp's own timed file: no name is another's rate
                and not any(a[1:] in found for a in found if a[0] in "va")
            )
        )
    )
    count = draw(st.integers(3, 25))
    steps = draw(
        st.lists(st.integers(1_000_000, 50_000_000), min_size=count - 1, max_size=count - 1)
    )
    start = 1_700_000_000_000_000_000 + draw(st.integers(0, 10**12))
    stamps = start + np.concatenate([[0], np.cumsum(steps)]).astype(np.int64)
    q = np.array(
        draw(
            st.lists(
                st.lists(_VALUES, min_size=len(names), max_size=len(names)),
                min_size=count,
                max_size=count,
            )
        )
    )
    orders = draw(st.lists(st.permutations(range(len(names))), min_size=count, max_size=count))
    return names, stamps, q, np.array(orders)


_STORES = {1: get_typestore(Stores.ROS1_NOETIC), 2: get_typestore(Stores.ROS2_HUMBLE)}


def _bag(path: Path, ros: int, storage: str, names, stamps, q, orders) -> Path:
    """A ``/joint_states`` bag written by rosbags: message k lists the joints in ``orders[k]``."""
    store = _STORES[ros]
    types = store.types
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer, serialize = Writer(path, version=9, storage_plugin=plugin), store.serialize_cdr
    with writer:
        connection = writer.add_connection(
            "/joint_states", "sensor_msgs/msg/JointState", typestore=store
        )
        for ns, row, order in zip(stamps.tolist(), q, orders):
            header = types["std_msgs/msg/Header"](
                **({"seq": 0} if ros == 1 else {}),
                stamp=types["builtin_interfaces/msg/Time"](
                    sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000
                ),
                frame_id="",
            )
            message = types["sensor_msgs/msg/JointState"](
                header=header,
                name=[names[k] for k in order],
                position=row[order].copy(),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            )
            # received 2 ms after its stamp, as a recorder does
            writer.write(connection, ns + 2_000_000, serialize(message, connection.msgtype))
    return path


@settings(
    max_examples=10,  # three bags written and read twice each: 0.3 s an example
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(joint_motions())
def test_one_joint_motion_reads_back_identical_from_every_reader(motion):
    names, stamps, q, orders = motion
    # seconds from the first stamp, exact to the nanosecond (as the bag reader and a logger give it)
    t = (stamps - stamps[0]).astype(float) * 1e-9
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        csv = folder / "joints.csv"
        csv.write_text(
            "t,"
            + ",".join(names)
            + "\n"
            + "".join(
                ",".join(repr(float(v)) for v in [time, *row]) + "\n" for time, row in zip(t, q)
            )
        )
        read = read_recording(csv)
        assert read.kind == "joints" and read.names == names
        np.testing.assert_array_equal(read.values, q)
        np.testing.assert_array_equal(read.t, t)
        # an .npy array holds positions (no names): read as the numbers, unless they do not move
        # (a demonstration of positions must: refused, saying so)
        np.save(folder / "joints.npy", q)
        if np.max(np.abs(q - q[0])) >= get_limits().min_extent:
            np.testing.assert_array_equal(read_recording(folder / "joints.npy").values, q)
        else:
            with pytest.raises(ValueError, match="degenerate|barely moves"):
                read_recording(folder / "joints.npy")
        for label, ros, storage in (
            ("r1.bag", 1, ""),
            ("mcap", 2, "mcap"),
            ("sqlite", 2, "sqlite3"),
        ):
            bag = _bag(folder / label, ros, storage, names, stamps, q, orders)
            chosen = read_bag(bag, joints=names)
            assert chosen.names == names and chosen.units == "rad", label
            np.testing.assert_array_equal(chosen.values, q, err_msg=label)
            np.testing.assert_array_equal(chosen.t, t, err_msg=label)
            # every joint, in the first message's order
            every = read_bag(bag, joints=True)
            assert every.names == [names[k] for k in orders[0]], label
            np.testing.assert_array_equal(every.values, q[:, orders[0]], err_msg=label)
