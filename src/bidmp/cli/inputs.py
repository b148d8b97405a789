"""Reading a demonstration file for the ``bidmp`` commands: columns, units (declared, requested,
the model's), preparation of timed input."""

from __future__ import annotations

import argparse
from pathlib import Path

_MODEL_EXTENT_RATIO = 20.0  # a demonstration this many times larger or smaller than the model's is in another unit

TIMED_INPUT = ("A timed DEMO (a CSV t column in seconds, or a timed .npy) is prepared unless --raw: the idle start "
               "and end are trimmed (speed below 5 % of the peak), the noise is removed by a zero-phase low-pass "
               "filter (--cutoff, default 6 Hz) and the samples are resampled to uniform time. A CSV may declare its "
               "unit in a first line '# units: mm'; --units converts it.")


def demo_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--units", default=None, metavar="UNIT", choices=("m", "cm", "mm"),
                        help="length unit (m, cm, mm): of the demonstration, or the one to convert a file that declares "
                             "another to")
    parser.add_argument("--columns", default=None, metavar="MAP",
                        help="which CSV columns are time and positions, e.g. t=timestamp,x=ee_x,y=ee_y,z=ee_z "
                             "(and qx,qy,qz,qw for poses); other columns are ignored")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--prepare", action="store_true", help="prepare timed input: trim idle ends, filter, uniform time (the default)")
    mode.add_argument("--raw", action="store_true", help="use a timed demonstration as recorded (no trimming or filtering)")
    parser.add_argument("--cutoff", type=float, default=6.0, metavar="HZ", help="low-pass cutoff for timed input in Hz (default 6)")


def bag_options(parser: argparse.ArgumentParser) -> None:
    """What ``bidmp fit`` reads from a ROS bag (bidmp.io.bags; the ros extra)."""
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--topic", default=None, metavar="TOPIC",
                        help="bag: the PoseStamped, TransformStamped or JointState topic to read (default: the only one)")
    source.add_argument("--tf", nargs=2, default=None, metavar=("PARENT", "CHILD"),
                        help="bag: the transform from frame PARENT to frame CHILD on /tf and /tf_static")
    parser.add_argument("--joints", nargs="*", default=None, metavar="NAME",
                        help="bag: joint states, these joints in this order (none named: every joint)")


def bag_recording(args: argparse.Namespace):
    """The bag ``args.demo`` read as its options say, once per command (or None: not a bag)."""
    from ..io.bags import is_bag, read_bag

    if not is_bag(args.demo):
        return None
    if getattr(args, "_bag", None) is None:
        joints = getattr(args, "joints", None)
        args._bag = read_bag(args.demo, topic=getattr(args, "topic", None),
                             tf=None if getattr(args, "tf", None) is None else tuple(args.tf),
                             joints=None if joints is None else (joints or True))
    return args._bag


# -- input ------------------------------------------------------------------------------------------
def is_pose_file(path) -> bool:
    """Whether ``path`` is a CSV whose header names a pose (``...,qx,qy,qz,qw``)."""
    if not str(path).lower().endswith((".csv", ".txt")) or not Path(path).is_file():
        return False  # (a FIFO or a device is refused by the reader, never opened here: it would block)
    try:
        with open(path, encoding="utf-8-sig") as handle:
            for _ in range(16):
                header = handle.readline(4096)
                if not header.lstrip().startswith("#"):
                    break
    except OSError:
        return False
    names = {name.strip().lower() for name in header.replace(";", ",").split(",")}
    return {"qx", "qy", "qz", "qw"} <= names


def model_dmp(model):
    """The position DMP of any model class (its units and workspace)."""
    from ..primitives.cartesian import CartesianDMP
    from ..incremental.cartesian import CartesianBiDMP
    from ..incremental.bidmp import BiDMP

    if isinstance(model, CartesianBiDMP):
        return model_dmp(model.__dict__.get("cartesian_", model.cartesian))
    if isinstance(model, CartesianDMP):
        return model.position_
    if isinstance(model, BiDMP):
        return model.__dict__.get("dmp_", model.dmp)
    return model


def _match_units(path, positions, units: str, model, what: str) -> str:
    """The demonstration's units against the model's: the same, converted on request before, or
    refused naming both; unknown units are judged by the size of the motion."""
    import numpy as np

    from ..tasks.metrics import path_extent

    dmp = model_dmp(model)
    model_units = dmp.units_
    if model_units and units and units != model_units:
        raise ValueError(f"{path} is in {units} but the model {what} is in {model_units}: pass --units {model_units} to "
                         f"convert it")
    if units or not model_units:
        return units or model_units
    extent, reference = path_extent(positions), path_extent(dmp.rollout())
    ratio = extent / max(reference, np.finfo(float).tiny)
    if not 1.0 / _MODEL_EXTENT_RATIO <= ratio <= _MODEL_EXTENT_RATIO:
        raise ValueError(f"{path} declares no units and its motion ({extent:.4g}) is {ratio:.3g} times the model's "
                         f"({reference:.4g} {model_units}): it is in another unit; pass --units (m, cm, mm) to say which")
    return model_units


def read_input(path: str, args: argparse.Namespace, *, poses: bool = False, model=None, what: str = ""):
    """A demonstration file as the library wants it: ``(values, t or None, units, how)``.

    Positions (T, D) or poses (T, 7), in ``--units`` (converted from the file's declared unit if
    it has another), checked against ``model``'s units; timed input prepared unless ``--raw``.
    """
    from .._units import check_units, conversion
    from ..io.trajectories import declared_units, is_joint_recording, read_trajectory
    from ..io.poses import read_poses

    requested = check_units(args.units or "", "--units")
    bag = bag_recording(args) if path == getattr(args, "demo", None) else None
    if bag is not None:  # header stamps; metres (poses) or radians (joints: no length unit)
        if (bag.kind == "pose") != poses:
            raise ValueError(f"{path}: {bag.source} holds {'poses' if bag.kind == 'pose' else 'joint states'}")
        values, times, declared = bag.values, bag.t, ("m" if bag.kind == "pose" else "rad")
    else:
        values, times = (read_poses if poses else read_trajectory)(path, columns=args.columns)
        declared = declared_units(path) if str(path).lower().endswith((".csv", ".txt")) else ""
        if not declared and not poses and is_joint_recording(path):  # t,<joint names>: angles in radians
            declared = "rad"
    notes = []
    if declared and requested and declared != requested:
        values = values.copy()
        values[:, : 3 if poses else values.shape[1]] *= conversion(declared, requested)
        notes.append(f"converted from {declared} (declared in the file) to {requested}")
    units = requested or declared
    if model is not None:
        units = _match_units(path, values[:, :3] if poses else values, units, model, what)
    if times is None or args.raw:
        how = "as recorded" if times is None else f"as recorded ({times[-1] - times[0]:.3f} s)"
    elif poses:
        from ..demonstrations.prepare import prepare_poses

        values, times, info = prepare_poses(values, times, cutoff_hz=args.cutoff, units=units)
        how = (f"prepared: {info.rate_hz:.4g} Hz, low-pass {info.cutoff_hz:g} Hz, motion {info.start_s:.3g}-"
               f"{info.end_s:.3g} s of the recording")
    else:
        from ..demonstrations.prepare import prepare

        prepared, info = prepare(values, times, cutoff_hz=args.cutoff, units=units)
        values, times = prepared.y, prepared.t
        how = (f"prepared: kept {info.start_s:.2f}-{info.end_s:.2f} s, low-pass {info.cutoff_hz:g} Hz at "
               f"{info.rate_hz:.1f} Hz, peak speed {info.peak_speed:.4g} {units or 'units'}/s")
    return values, times, units, "; ".join([how, *notes])


def scene_option(args: argparse.Namespace, units: str):
    """The scene of ``--scene`` (extend, rollout), in the model's units (refused in another)."""
    scenario = scenario_option(args, units)
    return None if scenario is None else scenario.scene


def scenario_option(args: argparse.Namespace, units: str):
    """The scenario of ``--scene``, which must have a scene in the model's units (None without one)."""
    if args.scene is None:
        return None
    from ..tasks.scenarios import load

    scenario = load(args.scene, allow_outside_files=args.allow_outside_files)
    if scenario.scene is None:
        raise ValueError(f"--scene: scenario {args.scene} has no \"scene\" key")
    if units and scenario.units and scenario.units != units:
        raise ValueError(f"--scene: the scene of {args.scene} is in {scenario.units} but the model is in {units}; "
                         f"use a scene in {units}")
    return scenario
