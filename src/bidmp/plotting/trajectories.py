"""Figures of motions: demonstrations and rollouts, the generalisation example, recordings."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._checks import (
    SLOWEST_HZ,
    as_points,
    as_trajectory,
    as_vector,
    check_limit,
    check_path,
    short_token,
)
from ..primitives.timing import check_timestamps
from ._base import _figure, _label_axes, _matplotlib, _save, _sequence, _text

__all__ = ["plot_trajectories", "plot_rollout", "plot_generalisation", "plot_recordings"]


def plot_trajectories(
    path: str | os.PathLike,
    demonstration: np.ndarray,
    trajectories: Sequence[np.ndarray] = (),
    labels: Sequence[str] | None = None,
    goals: np.ndarray | None = None,
    title: str = "",
    units: str = "",
) -> Path:
    """Plot a demonstration (thick grey), generated trajectories and their goals (stars).

    Parameters
    ----------
    path : path of the PNG to write.
    demonstration : array, shape (T, D), D = 2 or 3 (D = 1 is plotted against the sample index).
    trajectories : sequence of arrays (n, D).
    labels : one legend entry per trajectory (optional).
    goals : array, shape (G, D), optional; drawn as stars.
    """
    demonstration = as_trajectory(demonstration, "demonstration", min_points=1, allow_static=True)
    n_dims = demonstration.shape[1]
    if n_dims not in (1, 2, 3):
        raise ValueError(
            f"demonstration: can only plot 1-, 2- or 3-D trajectories, got D = {n_dims}"
        )
    trajectories = [
        as_trajectory(t, f"trajectories[{i}]", min_points=1, allow_static=True)
        for i, t in enumerate(_sequence(trajectories, "trajectories"))
    ]
    for index, trajectory in enumerate(trajectories):
        if trajectory.shape[1] != n_dims:
            raise ValueError(
                f"trajectories[{index}] has D = {trajectory.shape[1]}, the demonstration D = {n_dims}"
            )
    check_limit(len(trajectories), "max_targets", "trajectories: the number drawn")
    if goals is not None:
        goals = as_points(goals, n_dims, "goals")
        check_limit(goals.shape[0], "max_targets", "goals: the number drawn")
    if labels is not None:
        labels = [
            _text(label, f"labels[{index}]", 200)
            for index, label in enumerate(_sequence(labels, "labels"))
        ]
    title, units = _text(title, "title", 300), _text(units, "units", 16)
    path = check_path(path)
    mpl, fig, ax = _figure(n_dims == 3)

    def coords(points: np.ndarray):
        points = np.asarray(points, dtype=float)
        if n_dims == 1:
            return np.arange(len(points)), points[:, 0]
        return tuple(points[:, i] for i in range(n_dims))

    ax.plot(*coords(demonstration), color="0.55", linewidth=4, alpha=0.6, label="demonstration")
    ax.scatter(
        *[[c[0]] for c in coords(demonstration)], color="k", marker="o", zorder=5, label="start"
    )
    colours = mpl.cm.viridis(np.linspace(0.0, 0.9, max(len(trajectories), 1)))
    for index, trajectory in enumerate(trajectories):
        label = labels[index] if labels is not None and index < len(labels) else None
        ax.plot(*coords(trajectory), color=colours[index], linewidth=1.5, label=label)
    if goals is not None and n_dims > 1:
        ax.scatter(
            *[goals[:, i] for i in range(n_dims)],
            marker="*",
            s=140,
            color="crimson",
            zorder=6,
            label="goals",
        )
    _label_axes(ax, n_dims, units)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return _save(fig, path)


def plot_rollout(
    path: str | os.PathLike,
    demonstration: np.ndarray,
    trajectory,
    title: str = "rollout",
    units: str = "",
) -> Path:
    """A timed rollout: its path beside the demonstration's (left; 2-D or 3-D, more dimensions
    per coordinate against time) and its speed and acceleration over time (right; the norms, in
    units/s and units/s², the limits a robot checks first). A pose rollout
    (:class:`~bidmp.primitives.cartesian.PoseTrajectory`) also shows its orientation: the tool's
    frame (x red, y green, z blue) at twelve poses along the path, and a third panel with the turn
    about the tool's own z axis and the tilt of that axis from the start's, in degrees, over time.

    Parameters
    ----------
    path : path of the PNG to write.
    demonstration : (T, D) the model's own reproduction or demonstration.
    trajectory : bidmp.Trajectory or PoseTrajectory.
    """
    from ..primitives.timing import TimedMotion

    if not isinstance(trajectory, TimedMotion):
        raise TypeError(
            f"trajectory must be a bidmp.Trajectory or PoseTrajectory, got {type(trajectory).__name__}"
        )
    check_path(path)
    title, units = _text(title, "title", 200), _text(units, "units", 20)
    demonstration = as_trajectory(demonstration, "demonstration", min_points=1, allow_static=True)
    n_dims = trajectory.y.shape[1]
    quaternions = getattr(trajectory, "q", None)
    panels = 2 if quaternions is None else 3
    mpl = _matplotlib()
    fig = mpl.figure(figsize=(6.0 * panels, 5.0), dpi=110)
    spatial = n_dims in (2, 3)
    ax = fig.add_subplot(1, panels, 1, projection="3d" if n_dims == 3 else None)
    if spatial:
        ax.plot(
            *demonstration[:, :n_dims].T, color="0.55", linewidth=4, alpha=0.6, label="reproduction"
        )
        ax.plot(*trajectory.y.T, color="C0", linewidth=1.5, label="rollout")
        ax.plot(
            *[[c] for c in trajectory.y[-1]],
            marker="*",
            markersize=12,
            color="crimson",
            linestyle="none",
            label="end",
        )
        if quaternions is not None:
            _draw_frames(ax, trajectory.y, quaternions)
        _label_axes(ax, n_dims, units)
    else:  # a joint-space (or 1-D) motion: each coordinate against time
        names = list(getattr(trajectory, "names", ())) or [f"x{index}" for index in range(n_dims)]
        for index in range(n_dims):
            ax.plot(trajectory.t, trajectory.y[:, index], label=names[index])
        ax.set_xlabel("t [s]")
        ax.set_ylabel("position" + (f" [{units}]" if units else ""))
    ax.set_title(title)
    ax.legend(loc="best", fontsize=8)
    rates = fig.add_subplot(1, panels, 2)
    suffix = units or "units"
    rates.plot(
        trajectory.t, np.linalg.norm(trajectory.yd, axis=1), color="C0", label=f"speed [{suffix}/s]"
    )
    rates.set_xlabel("t [s]")
    rates.set_ylabel(f"speed [{suffix}/s]", color="C0")
    twin = rates.twinx()
    twin.plot(
        trajectory.t,
        np.linalg.norm(trajectory.ydd, axis=1),
        color="C3",
        label=f"acceleration [{suffix}/s²]",
    )
    twin.set_ylabel(f"acceleration [{suffix}/s²]", color="C3")
    rates.set_title(
        f"peak speed {trajectory.peak_speed():.3g} {suffix}/s, peak acceleration "
        f"{trajectory.peak_acceleration():.3g} {suffix}/s²",
        fontsize=10,
    )
    rates.grid(True, alpha=0.3)
    if quaternions is not None:
        turn, tilt = _tool_angles(quaternions)
        angles = fig.add_subplot(1, panels, 3)
        angles.plot(trajectory.t, turn, color="C2", label="turn about the tool's z axis")
        angles.plot(trajectory.t, tilt, color="C4", label="tilt of the tool's z axis")
        angles.set_xlabel("t [s]")
        angles.set_ylabel("angle from the start's orientation [deg]")
        angles.set_title(
            f"orientation: turned {turn[-1]:.4g} deg, tilted {tilt[-1]:.3g} deg at the end",
            fontsize=10,
        )
        angles.legend(loc="best", fontsize=8)
        angles.grid(True, alpha=0.3)
        # room for the middle panel's second axis
        fig.subplots_adjust(left=0.04, right=0.97, wspace=0.42)
    return _save(fig, path)


def _tool_angles(quaternions) -> tuple[np.ndarray, np.ndarray]:
    """The turn about the tool's own z axis and the tilt of that axis, from the first orientation
    (degrees; the turn unwrapped, so 540 degrees of unscrewing read as 540).

    The relative rotation ``q0⁻¹ q`` is split into a twist about z and a swing of the z axis:
    twist ``2·atan2(qz, qw)``, swing the angle between the two z axes.

    Parameters
    ----------
    quaternions : (n, 4) unit quaternions ``qx, qy, qz, qw``.

    Returns
    -------
    turn, tilt : arrays (n,), degrees.
    """
    from scipy.spatial.transform import Rotation

    q = as_trajectory(quaternions, "quaternions", min_points=1, allow_static=True)
    if q.shape[1] != 4:
        raise ValueError(f"quaternions must have 4 columns (qx, qy, qz, qw), got {q.shape[1]}")
    relative = (Rotation.from_quat(q[:1]).inv() * Rotation.from_quat(q)).as_quat()
    turn = np.unwrap(2.0 * np.arctan2(relative[:, 2], relative[:, 3]))
    axis = Rotation.from_quat(relative).apply([0.0, 0.0, 1.0])
    tilt = np.arccos(np.clip(axis[:, 2], -1.0, 1.0))
    return np.degrees(turn), np.degrees(tilt)


def _draw_frames(ax, positions: np.ndarray, quaternions: np.ndarray, count: int = 12) -> None:
    """The tool's frame at ``count`` poses along the path: x red, y green, z blue, each a tenth
    of the path's extent (3-D only)."""
    from scipy.spatial.transform import Rotation

    if positions.shape[1] != 3:
        return
    extent = float(np.max(np.ptp(positions, axis=0))) or 1.0
    chosen = np.unique(
        np.linspace(0, len(positions) - 1, min(count, len(positions))).round().astype(int)
    )
    axes = Rotation.from_quat(quaternions[chosen]).as_matrix() * (0.1 * extent)
    for column, colour in enumerate(("tab:red", "tab:green", "tab:blue")):
        ax.quiver(
            *positions[chosen].T,
            *axes[:, :, column].T,
            color=colour,
            linewidth=1.0,
            arrow_length_ratio=0.15,
            label=f"tool {'xyz'[column]} axis",
        )


def plot_generalisation(path: str | os.PathLike, result) -> Path:
    """Two panels for a :class:`bidmp.tasks.evaluation.GeneralisationResult` (2-D): the rollouts to moved
    goals with the paper's fixed horizon (left) and run to convergence (right)."""
    from .._checks import check_members

    check_members(
        result,
        ("fixed_horizon", "converged", "demonstration"),
        "result",
        "a GeneralisationResult (bidmp.experiments.lasa_generalisation)",
    )
    mpl = _matplotlib()
    fig, axes = mpl.subplots(1, 2, figsize=(12.0, 5.5), dpi=110)
    panels = (
        (
            result.fixed_horizon,
            f"T = {result.demonstration.shape[0]} steps (paper): end-point gain c = {result.endpoint_gain:.3f}",
        ),
        (
            result.converged,
            f"{result.converged.shape[1]} steps (run to convergence): c = {result.endpoint_gain_converged:.1e}",
        ),
    )
    colours = mpl.cm.viridis(np.linspace(0.0, 0.85, len(result.goals)))
    for ax, (rollouts, title) in zip(axes, panels):
        demo = result.demonstration
        ax.plot(demo[:, 0], demo[:, 1], color="0.55", linewidth=4, alpha=0.6, label="demonstration")
        ax.plot(
            result.reproduction[:, 0],
            result.reproduction[:, 1],
            "k--",
            linewidth=1,
            label="reproduction",
        )
        for colour, rollout, goal in zip(colours, rollouts, result.goals):
            ax.plot(rollout[:, 0], rollout[:, 1], color=colour, linewidth=1.3)
            ax.plot(*goal, marker="*", markersize=12, color=colour, markeredgecolor="crimson")
            ax.plot(*rollout[-1], marker="x", markersize=7, color="crimson")
        ax.plot(*demo[0], "ko", label="start")
        ax.plot([], [], "*", color="0.3", markeredgecolor="crimson", label="moved goal")
        ax.plot([], [], "x", color="crimson", label="end point")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("x [mm]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("y [mm]")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(f"LASA {result.shape}: one demonstration, DMP rollouts to moved goals")
    return _save(fig, path)


def _recording(entry, index: int) -> tuple:
    """One entry of :func:`plot_recordings`' ``recordings``, checked."""
    from ..demonstrations import PrepareInfo
    from ..primitives.timing import Trajectory

    where = f"recordings[{index}]"
    if not isinstance(entry, (tuple, list)) or len(entry) != 6:
        raise TypeError(
            f"{where} must be (name, y, t, prepared, info, moved), got {short_token(entry, 30)}"
        )
    name, y, t, prepared, info, moved = entry
    name = _text(name, f"{where}'s name", 100)
    y = as_trajectory(y, f"{where}'s y", min_points=2)
    t = check_timestamps(t, y.shape[0], f"{where}'s t")
    if not isinstance(prepared, Trajectory) or not isinstance(info, PrepareInfo):
        raise TypeError(f"{where}: prepared and info must be what bidmp.prepare returns")
    if moved is not None and not isinstance(moved, Trajectory):
        raise TypeError(
            f"{where}: moved must be a bidmp.Trajectory or None, got {type(moved).__name__}"
        )
    return name, y, t, prepared, info, moved


def plot_recordings(path, recordings) -> Path:
    """Kinesthetic recordings raw and prepared, the DMP's rollout to a moved goal, and the speed
    profiles in real time (top view, side view, speed).

    Parameters
    ----------
    recordings : list of (name, y, t, prepared, info, moved)
        ``y``, ``t``: the recording; ``prepared``, ``info``: :func:`bidmp.prepare`'s result;
        ``moved``: a :class:`bidmp.Trajectory` (the rollout to the moved goal), or None.
    """
    recordings = [
        _recording(entry, index) for index, entry in enumerate(_sequence(recordings, "recordings"))
    ]
    if not recordings:
        raise ValueError("recordings is empty: nothing to draw")
    path = check_path(path)
    mpl = _matplotlib()
    fig, (top, side, speed) = mpl.subplots(1, 3, figsize=(12.0, 4.6), dpi=110)
    colours = mpl.cm.tab10(np.arange(10))
    for index, (name, y, t, prepared, info, moved) in enumerate(recordings):
        colour = colours[index % 10]
        top.plot(y[:, 0], y[:, 1], color=colour, alpha=0.35, linewidth=3, label=f"{name} (raw)")
        side.plot(y[:, 0], y[:, 2], color=colour, alpha=0.35, linewidth=3)
        raw_speed = np.linalg.norm(np.gradient(y, t, axis=0), axis=1)
        speed.plot(t - t[0], raw_speed, color=colour, alpha=0.25, linewidth=0.6)
        speed.plot(
            prepared.t + info.start_s,
            np.linalg.norm(prepared.yd, axis=1),
            color=colour,
            linewidth=2,
            label=f"{name}: prepared, kept {info.start_s:.2f}-{info.end_s:.2f} s",
        )
        if moved is not None:
            top.plot(
                moved.y[:, 0],
                moved.y[:, 1],
                color=colour,
                linewidth=1.2,
                label="DMP to the moved goal",
            )
            side.plot(moved.y[:, 0], moved.y[:, 2], color=colour, linewidth=1.2)
            speed.plot(
                moved.t + info.start_s,
                np.linalg.norm(moved.yd, axis=1),
                color=colour,
                linestyle="--",
                linewidth=1,
            )
            top.plot(moved.y[-1, 0], moved.y[-1, 1], marker="*", markersize=12, color="crimson")
            side.plot(moved.y[-1, 0], moved.y[-1, 2], marker="*", markersize=12, color="crimson")
    units = recordings[0][3].units if recordings else ""
    suffix = f" [{units}]" if units else ""
    top.set(xlabel="x" + suffix, ylabel="y" + suffix, title="top view")
    side.set(xlabel="x" + suffix, ylabel="z" + suffix, title="side view")
    speed.set(
        xlabel="time in the recording [s]",
        ylabel=f"speed [{units or 'units'}/s]",
        title="speed: raw (thin), prepared, rollout (dashed)",
    )
    speed.set_ylim(
        0.0, 1.3 * max(float(np.max(np.linalg.norm(r[3].yd, axis=1))) for r in recordings)
    )
    top.legend(fontsize=7, loc="lower right")
    speed.legend(fontsize=7, loc="upper right")
    for axes in (top, side, speed):
        axes.grid(True, alpha=0.3)
    fig.tight_layout()
    return _save(fig, path)


def plot_rhythm(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    path: str | os.PathLike,
    recording: np.ndarray,
    t: np.ndarray,
    trajectory,
    frequency: float,
    uncertainty: float = 0.0,
    title: str = "rhythm",
    units: str = "",
) -> Path:
    """A rhythmic motion: the learned cycle over the recording's path (left: the first two or
    three coordinates), its phase portrait (middle: each coordinate's velocity against its
    position about the mean, the recording's by central differences in grey), and the recording's
    spectrum with the estimated frequency marked (right).

    Parameters
    ----------
    path : path of the PNG to write.
    recording : (T, D) the recording (units); t : (T,) its stamps (s).
    trajectory : bidmp.Trajectory of the learned rhythm (a few cycles).
    frequency, uncertainty : the estimate (Hz) and its standard error (Hz).
    """
    from ..primitives.timing import TimedMotion

    if not isinstance(trajectory, TimedMotion):
        raise TypeError(f"trajectory must be a bidmp.Trajectory, got {type(trajectory).__name__}")
    from .._checks import check_real

    check_path(path)
    title, units = _text(title, "title", 200), _text(units, "units", 20)
    frequency = check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
    uncertainty = check_real(uncertainty, "uncertainty", nonnegative=True, maximum=1e3)
    recording = as_trajectory(recording, "recording", min_points=8)
    t = check_timestamps(t, recording.shape[0])
    n_dims = min(recording.shape[1], trajectory.y.shape[1], 3)
    mpl = _matplotlib()
    fig = mpl.figure(figsize=(17.0, 5.0), dpi=110)
    ax = fig.add_subplot(1, 3, 1, projection="3d" if n_dims == 3 else None)
    if n_dims >= 2:
        ax.plot(*recording[:, :n_dims].T, color="0.6", linewidth=0.8, label="recording")
        ax.plot(*trajectory.y[:, :n_dims].T, color="C0", linewidth=2.0, label="learned cycle")
        _label_axes(ax, n_dims, units)
    else:
        ax.plot(t - t[0], recording[:, 0], color="0.6", linewidth=0.8, label="recording")
        ax.plot(trajectory.t, trajectory.y[:, 0], color="C0", linewidth=2.0, label="learned")
        ax.set_xlabel("t [s]")
    ax.set_title(title)
    ax.legend(loc="best", fontsize=8)
    portrait = fig.add_subplot(1, 3, 2)
    velocity = np.gradient(recording, t, axis=0)
    suffix = units or "units"
    for index in range(n_dims):
        centre = trajectory.y[:, index].mean()
        portrait.plot(recording[:, index] - centre, velocity[:, index], color="0.8", linewidth=0.5)
        portrait.plot(
            trajectory.y[:, index] - centre, trajectory.yd[:, index], label=f"coordinate {index}"
        )
    portrait.set_xlabel(f"position about the centre [{suffix}]")
    portrait.set_ylabel(f"velocity [{suffix}/s]")
    portrait.set_title("phase portrait (recording in grey)", fontsize=10)
    portrait.legend(loc="best", fontsize=8)
    portrait.grid(True, alpha=0.3)
    spectrum = fig.add_subplot(1, 3, 3)
    uniform = np.linspace(t[0], t[-1], recording.shape[0])
    resampled = np.column_stack([np.interp(uniform, t, column) for column in recording.T])
    resampled -= resampled.mean(axis=0)
    power = np.sum(
        np.abs(np.fft.rfft(resampled * np.hanning(len(uniform))[:, None], axis=0)) ** 2, 1
    )
    frequencies = np.fft.rfftfreq(len(uniform), (t[-1] - t[0]) / (len(uniform) - 1))
    shown = frequencies <= 6.0 * frequency
    spectrum.semilogy(frequencies[shown], power[shown] + 1e-300, color="C0")
    spectrum.axvline(frequency, color="crimson", label=f"{frequency:.4g} ± {uncertainty:.2g} Hz")
    spectrum.set_xlabel("frequency [Hz]")
    spectrum.set_ylabel("power")
    spectrum.set_title("spectrum of the recording and the estimated frequency", fontsize=10)
    spectrum.legend(loc="best", fontsize=8)
    spectrum.grid(True, alpha=0.3)
    fig.subplots_adjust(left=0.03, right=0.98, wspace=0.3)
    return _save(fig, path)


def plot_distribution(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    path: str | os.PathLike,
    demonstrations,
    mean: np.ndarray,
    std: np.ndarray,
    conditioned: np.ndarray | None = None,
    conditioned_std: np.ndarray | None = None,
    points=None,
    title: str = "distribution",
    units: str = "",
    times=None,
) -> Path:
    """A motion learned from several demonstrations: per coordinate against the phase (the share
    of the motion's time) or against time, the demonstrations (grey), the mean with its ±2σ band
    (blue), and a conditioned result with its own band (orange) and the points it was conditioned
    on (black).

    Parameters
    ----------
    path : path of the PNG to write.
    demonstrations : list of (T_i, D) arrays (each drawn over its own phase [0, 1]).
    mean, std : (L, D) over L phases evenly in [0, 1].
    conditioned, conditioned_std : (L', D), optional.
    points : (phases (K,), values (K, D)), optional.
    times : dict, optional
        Draw against time (s) instead: ``{"demonstrations": [(T_i,) ...], "mean": (L,),
        "conditioned": (L',)}`` (the last when ``conditioned`` is given); ``points``' first entry
        is then in seconds. A motion's own time base: a DMP's mean motion runs on past its
        demonstrations' time to come to rest, and drawn over [0, 1] beside them it was squeezed
        off them.
    """
    check_path(path)
    title, units = _text(title, "title", 200), _text(units, "units", 20)
    demos, mean, std, points, conditioned, spread = _distribution_inputs(
        demonstrations, mean, std, points, (conditioned, conditioned_std), times
    )
    n_dims = mean.shape[1]
    axis = _time_axes(times, demos, mean, conditioned)
    mpl = _matplotlib()
    fig = mpl.figure(figsize=(5.5 * n_dims, 4.5), dpi=110)
    phase = axis["mean"]
    suffix = f" [{units}]" if units else ""
    for d in range(n_dims):
        ax = fig.add_subplot(1, n_dims, d + 1)
        for y, along in zip(demos, axis["demonstrations"]):
            ax.plot(along, y[:, d], color="0.7", linewidth=0.8)
        ax.fill_between(
            phase, mean[:, d] - 2 * std[:, d], mean[:, d] + 2 * std[:, d], color="C0", alpha=0.25
        )
        ax.plot(phase, mean[:, d], color="C0", linewidth=2.0, label="mean ± 2σ")
        if conditioned is not None:
            c_phase = axis["conditioned"]
            if spread is not None:
                ax.fill_between(
                    c_phase,
                    conditioned[:, d] - 2 * spread[:, d],
                    conditioned[:, d] + 2 * spread[:, d],
                    color="C1",
                    alpha=0.25,
                )
            ax.plot(c_phase, conditioned[:, d], color="C1", linestyle="--", label="conditioned")
        if points is not None:
            at, values = points
            ax.plot(np.asarray(at), np.asarray(values)[:, d], "ko", label="conditioned on")
        ax.set_xlabel("time [s]" if times is not None else "phase (share of the motion's time)")
        ax.set_ylabel(f"coordinate {d}{suffix}")
        ax.grid(True, alpha=0.3)
        if d == 0:
            ax.set_title(title)
            ax.legend(loc="best", fontsize=8)
    return _save(fig, path)


def _distribution_inputs(demonstrations, mean, std, points, conditioned_pair, times) -> tuple:
    """:func:`plot_distribution`'s curves checked against one another, before anything is drawn:
    ``(demonstrations, mean, std, points, conditioned, its spread)``, every one with the mean's
    coordinates."""
    conditioned, conditioned_std = conditioned_pair
    demos = [
        as_trajectory(y, f"demonstrations[{i}]", min_points=2, allow_static=True)
        for i, y in enumerate(_sequence(demonstrations, "demonstrations"))
    ]
    mean = as_trajectory(mean, "mean", min_points=2, allow_static=True)
    try:
        std = as_points(std, mean.shape[1], "std")
    except ValueError as exc:
        raise ValueError(f"{exc} (mean has shape {mean.shape})") from None
    if std.shape != mean.shape or np.any(std < 0):
        raise ValueError(f"std must be non-negative, of mean's shape {mean.shape}, got {std.shape}")
    if points is not None:
        if not isinstance(points, (tuple, list)) or len(points) != 2:
            raise TypeError("points must be (phases (K,), values (K, D)) or None")
        at = as_vector(points[0], "points[0]")
        values = as_points(points[1], mean.shape[1], "points[1]")
        if values.shape[0] != at.shape[0] or at.min() < 0.0 or (times is None and at.max() > 1.0):
            raise ValueError(
                "points must be K phases in [0, 1] (times in s with times=) and K values of D "
                "coordinates"
            )
        points = (at, values)
    n_dims = mean.shape[1]
    for index, y in enumerate(demos):
        if y.shape[1] != n_dims:
            raise ValueError(
                f"demonstrations[{index}] has {y.shape[1]} coordinates, mean has {n_dims}"
            )
    spread = None
    if conditioned is not None:
        conditioned = as_trajectory(conditioned, "conditioned", min_points=2, allow_static=True)
        if conditioned.shape[1] != n_dims:
            raise ValueError(
                f"conditioned has {conditioned.shape[1]} coordinates, mean has {n_dims}"
            )
        if conditioned_std is not None:
            spread = as_points(conditioned_std, n_dims, "conditioned_std")
            if spread.shape != conditioned.shape or np.any(spread < 0):
                raise ValueError(
                    f"conditioned_std must be non-negative, of conditioned's shape "
                    f"{conditioned.shape}, got {spread.shape}"
                )
    elif conditioned_std is not None:
        raise ValueError("conditioned_std is the spread of conditioned: give conditioned too")
    return demos, mean, std, points, conditioned, spread


def _time_axes(times, demos: list, mean: np.ndarray, conditioned) -> dict:
    """The horizontal coordinates of :func:`plot_distribution`'s curves: phases evenly in [0, 1],
    or the given times (checked: one increasing time per row)."""
    if times is None:
        return {
            "demonstrations": [np.linspace(0.0, 1.0, y.shape[0]) for y in demos],
            "mean": np.linspace(0.0, 1.0, mean.shape[0]),
            "conditioned": None
            if conditioned is None
            else np.linspace(0.0, 1.0, np.shape(conditioned)[0]),
        }
    if not isinstance(times, dict):
        raise TypeError(f"times must be a dict of time arrays or None, got {type(times).__name__}")

    def checked(values, rows: int, name: str) -> np.ndarray:
        values = as_vector(values, f"times[{name!r}]")
        if values.shape[0] != rows or np.any(np.diff(values) < 0):
            raise ValueError(f"times[{name!r}] must be {rows} non-decreasing times (s)")
        return values

    given = _sequence(times.get("demonstrations", []), "times['demonstrations']")
    if len(given) != len(demos):
        raise ValueError(f"times['demonstrations'] must hold {len(demos)} time arrays")
    return {
        "demonstrations": [checked(t, y.shape[0], "demonstrations") for t, y in zip(given, demos)],
        "mean": checked(times.get("mean"), mean.shape[0], "mean"),
        "conditioned": None
        if conditioned is None
        else checked(times.get("conditioned"), np.shape(conditioned)[0], "conditioned"),
    }
