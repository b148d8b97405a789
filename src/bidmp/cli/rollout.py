"""``bidmp rollout``: a saved model rolled out to a goal, with limits, via-points, a scene to steer
round and a ROS bag out."""

from __future__ import annotations

import argparse

from .inputs import model_dmp, scenario_option

EXIT_OK = 0


def _timing_options(args: argparse.Namespace, dmp) -> dict:
    """trajectory() keywords from
    --rate/--n-steps/--duration/--max-speed/--max-acc/--max-jerk/--joint-limits/--fastest."""
    options = {"duration": args.duration}
    if args.rate is not None and args.n_steps is not None:
        raise ValueError("give --rate or --n-steps, not both")
    if args.rate is not None:
        if not 0 < args.rate <= 100_000:
            raise ValueError(f"--rate must be in (0, 100000] Hz, got {args.rate:g}")
        options["dt"] = 1.0 / args.rate
    elif args.n_steps is not None:
        from .._checks import check_int

        check_int(args.n_steps, "--n-steps", minimum=2, limit="max_steps")
        motion = dmp.tau * dmp.duration_ if args.duration is None else args.duration
        # the same motion, sampled more finely
        options["dt"] = dmp.settings().settle * motion / (args.n_steps - 1)
    limits = _limits(args, dmp)
    if limits:
        options["limits"] = {**limits, "fastest": args.fastest}
        if args.duration is not None:
            raise ValueError(
                "give --duration or --max-speed/--max-acc/--joint-limits, not both (the limits choose the duration)"
            )
        options.pop("duration")
    elif args.fastest:
        raise ValueError(
            "--fastest needs --max-speed, --max-acc or --joint-limits (the limits it may run up to)"
        )
    return options


def _limits(args: argparse.Namespace, dmp) -> dict:
    """The limits of --max-speed/--max-acc/--max-jerk (one value: on the speed's norm; one per
    dimension: per axis, a joint-space model's per-joint limits) or --joint-limits panda."""
    given = {
        key: value
        for key, value in (
            ("max_velocity", args.max_speed),
            ("max_acceleration", args.max_acc),
            ("max_jerk", args.max_jerk),
        )
        if value is not None
    }
    if args.joint_limits is not None:
        if given:
            raise ValueError("give --joint-limits or --max-speed/--max-acc/--max-jerk, not both")
        arm = _arm_limits(args)
        if dmp.n_dims_ != arm.n_joints:
            raise ValueError(
                f"--joint-limits {args.joint_limits}: that arm has {arm.n_joints} joints; this model has "
                f"{dmp.n_dims_} dimensions"
            )
        return {
            "max_velocity": arm.velocity,
            "max_acceleration": arm.acceleration,
            "max_jerk": arm.jerk,
            "norm": "axis",
        }
    if not given:
        return {}
    counts = {len(value) for value in given.values()}
    if counts - {1, dmp.n_dims_} or len(counts) > 1:
        raise ValueError(
            f"--max-speed/--max-acc/--max-jerk take one value (on the norm) or {dmp.n_dims_} (one per "
            f"dimension), the same count for each"
        )
    per_axis = counts == {dmp.n_dims_} and dmp.n_dims_ > 1
    return {key: (value if per_axis else value[0]) for key, value in given.items()} | {
        "norm": "axis" if per_axis else "norm"
    }


def _arm_limits(args: argparse.Namespace):
    """The JointLimits of --joint-limits: a built-in arm (panda, fr3, iiwa, xarm6, ur5), or the robot a scenario
    names (its "robot" key: a model or its own URDF's limits)."""
    from ..sim.robots import ROBOT_MODELS, robot_model

    if args.joint_limits in ROBOT_MODELS:
        return ROBOT_MODELS[args.joint_limits].limits
    from ..tasks.scenarios import load

    scenario = load(
        args.joint_limits, allow_outside_files=getattr(args, "allow_outside_files", False)
    )
    return robot_model(scenario.robot, scenario.base_dir).limits


def _skill_choice(args: argparse.Namespace, model):
    from ..primitives.registry import kind_of

    if not kind_of(model).skills:
        if args.skill is not None:
            raise ValueError(
                f"--skill needs a Bi-DMP model; {args.model} holds a {type(model).__name__}"
            )
        return None
    return (
        "nearest"
        if args.skill is None
        else (int(args.skill) if args.skill.lstrip("-").isdigit() else args.skill)
    )


def cmd_rollout(args: argparse.Namespace) -> int:
    import numpy as np

    from ..io.models import load_model
    from ..io.poses import save_poses
    from ..io.trajectories import save_trajectory
    from ..primitives.cartesian import angle_between

    args.robot_given = args.robot is not None
    from ..sim.robots import ROBOT_MODELS

    args.robot = args.robot or (args.joint_limits if args.joint_limits in ROBOT_MODELS else "panda")
    if not args.tool_length >= 0:
        raise ValueError(f"--tool-length must be >= 0 metres, got {args.tool_length:g}")
    model = load_model(args.model)
    from ..primitives.registry import kind_of

    kind = kind_of(model)  # what the model is decides the rollout: its family in the registry
    if kind.family == "rhythmic":
        from .rhythm import rollout_periodic

        return rollout_periodic(args, model)
    if kind.family == "several":
        from .several import rollout_several

        return rollout_several(args, model)
    rhythmic = ("cycles", "frequency", "anchor")
    if any(getattr(args, name) is not None for name in rhythmic) or args.from_rest:
        raise ValueError(
            f"--cycles, --frequency, --amplitude, --anchor and --from-rest are for a rhythmic model "
            f"(bidmp fit --periodic); {args.model} holds a {type(model).__name__}"
        )
    if args.amplitude is not None:
        raise ValueError("--amplitude is for a rhythmic model (bidmp fit --periodic)")
    if kind.family != "point":
        raise ValueError(f"{args.model} holds a {type(model).__name__}, which cannot be rolled out")
    dmp = model_dmp(model)
    poses = kind.poses
    _refuse_idle_arm(args, dmp, poses)
    skill = _skill_choice(args, model)
    options = {
        "goal": _joint_goal(args, dmp, poses),
        "start": args.start,
        **_timing_options(args, dmp),
    }
    # where the motion goes when --goal is not given: a Bi-DMP's latest skill's goal, else the DMP's
    point_skills = kind.skills and not kind.poses  # a Bi-DMP of points: its skills' goals
    default_goal = model.skill_goals_[-1] if point_skills else dmp.goal_
    if skill is not None:
        options["skill"] = skill
        goals = model.skill_goals_ if point_skills else model.position_.skill_goals_
        index = model.select_skill(
            default_goal if args.goal is None and point_skills else args.goal, skill
        )
        print(
            f"Bi-DMP with {model.n_skills} skills: using skill {index} (training goal "
            f"{np.array2string(goals[index], precision=3)})"
        )
    options.update(_rollout_extras(args, dmp, poses, default_goal))
    if not args.bag and (
        args.follow
        or args.orientation is not None
        or args.bag_topic is not None
        or args.stamp != "now"
    ):
        raise ValueError(
            "--follow, --orientation, --bag-topic and --stamp shape the bag: give --bag OUT"
        )
    trajectory = model.trajectory(**options)
    from .._units import check_speed

    # never write what no robot runs
    check_speed(trajectory.peak_speed(), dmp.units_, "the rolled-out motion", fast_only=True)
    from ..io.runs import output_files

    # -o, --bag and --plot appear together or not at all: each written beside its place, then
    # put in place once all are written
    with output_files() as outputs:
        path = (save_poses if poses else save_trajectory)(trajectory, outputs.path(args.output))
        bag = (
            _rollout_bag(args, trajectory, dmp, poses, outputs.path(args.bag)) if args.bag else None
        )
        if args.plot:
            from ..plotting.trajectories import plot_rollout

            figure = plot_rollout(
                outputs.path(args.plot),
                dmp.rollout(),
                trajectory,
                title="rollout",
                units=dmp.units_,
            )
    unit = dmp.units_ or "units"
    rate = 1.0 / (trajectory.t[1] - trajectory.t[0]) if len(trajectory) > 1 else float("nan")
    goal = trajectory.y[-1] if options["goal"] is None else np.asarray(options["goal"], dtype=float)
    print(
        f"rolled out {len(trajectory)} samples over {trajectory.duration:.4g} s ({rate:.4g} Hz) to goal "
        f"{np.array2string(goal, precision=4)}"
    )
    print(
        f"  end point {np.array2string(trajectory.y[-1], precision=4)}, distance to goal "
        f"{np.linalg.norm(trajectory.y[-1] - goal[: 3 if poses else None]):.4g} {unit}"
        + (
            f", {np.degrees(angle_between(trajectory.q[-1:], goal[None, 3:]))[0]:.3g} deg"
            if poses and goal.size == 7
            else ""
        )
    )
    print(
        f"  peak speed {trajectory.peak_speed():.4g} {unit}/s, peak acceleration {trajectory.peak_acceleration():.4g} "
        f"{unit}/s^2, initial acceleration {np.linalg.norm(trajectory.ydd[0]):.4g} {unit}/s^2"
    )
    for term in options.get("coupling") or ():
        clearance = term.clearance_
        print(
            f"  steered round the scene's parts: clearance {clearance.distance:.4g} {unit} to {clearance.part} "
            f"(margin {clearance.margin:g}; the target's parts {', '.join(term.excluded_) or 'none'} left out)"
        )
    print(f"wrote {outputs.shown(path)} (columns {','.join(trajectory.columns()[0])})")
    if bag is not None:
        print(f"wrote {outputs.shown(bag)}")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK


def _refuse_idle_arm(args: argparse.Namespace, dmp, poses: bool) -> None:
    """The arm's options act only where its inverse kinematics runs: --cartesian-goal, or a 3-D
    position model's --bag with --robot. Given anywhere else they are refused (none is dropped
    unread), and --base, --yaw, --tool-length too for a scenario's robot (the scenario places it
    and gives its tool)."""
    from ..sim.robots import ROBOT_MODELS

    given = {
        name: getattr(args, name) != args.unset_options[name]
        for name in ("base", "yaw", "tool_length")
    }
    ik_bag = bool(args.bag) and args.robot_given and not poses and dmp.n_dims_ == 3
    if args.cartesian_goal is not None or ik_bag:
        if args.robot not in ROBOT_MODELS and any(given.values()):
            flag = "--" + next(name for name, on in given.items() if on).replace("_", "-")
            raise ValueError(
                f"{flag} does not apply to the robot of a scenario (--robot {args.robot}): the "
                f"scenario places its arm and gives its tool"
            )
        return
    for name, on in (("robot", args.robot_given), *given.items()):
        if on:
            raise ValueError(
                f"--{name.replace('_', '-')} does not apply here: it {'is' if name == 'robot' else 'places'} "
                f"the arm whose inverse kinematics --cartesian-goal (a joint-space model) or a 3-D "
                f"position model's --bag with --robot uses, and neither is given"
            )


def _joint_goal(args: argparse.Namespace, dmp, poses: bool):
    """The goal of --goal, or of --cartesian-goal: a joint-space model's joints that put the
    robot's tool there (its IK, from the demonstrated goal's joints: the nearest solution)."""
    if args.cartesian_goal is None:
        return args.goal
    if args.goal is not None:
        raise ValueError("give --goal (joints) or --cartesian-goal (the tool's position), not both")
    import numpy as np

    from ..sim.kinematics import inverse_kinematics
    from ..sim.robots import ROBOT_MODELS

    arm = _arm(args, 1.0)
    robot = arm["robot"]
    n_joints = (ROBOT_MODELS[robot] if isinstance(robot, str) else robot).n_joints
    if poses or dmp.n_dims_ != n_joints:
        name = robot if isinstance(robot, str) else robot.name
        raise ValueError(
            f"--cartesian-goal is for a joint-space model of the {name}'s {n_joints} joints (t,<joint names> "
            f"or JointState input); this model has {7 if poses else dmp.n_dims_} dimensions: give --goal"
        )
    q = inverse_kinematics(
        np.asarray(args.cartesian_goal, dtype=float), units="m", seed=dmp.goal_, **arm
    )
    print(
        f"--cartesian-goal {args.cartesian_goal} m: the {args.robot}'s joints {np.array2string(q, precision=4)} rad "
        f"(inverse kinematics from the demonstrated goal's)"
    )
    return q


def _arm(args: argparse.Namespace, metres_per_unit: float) -> dict:
    """The arm of --robot for inverse kinematics, in metres: a built-in (at --base, turned by
    --yaw, --tool-length on its flange), or a scenario's robot where the scenario puts it, with
    the scenario's tool (its model, URDF and limits)."""
    import numpy as np

    from ..sim.robots import ROBOT_MODELS, robot_model, robot_placement

    if args.robot in ROBOT_MODELS:
        base = (
            np.zeros(3)
            if args.base is None
            else np.asarray(args.base, dtype=float) * metres_per_unit
        )
        return {"robot": args.robot, "base": base, "yaw": args.yaw, "tool_length": args.tool_length}
    from .._units import conversion
    from ..tasks.scenarios import load

    scenario = load(args.robot, allow_outside_files=getattr(args, "allow_outside_files", False))
    scale = conversion(scenario.units, "m")
    base, yaw = robot_placement(scenario)
    tool = args.tool_length if scenario.scene is None else scenario.scene.tool.length * scale
    return {
        "robot": robot_model(scenario.robot, scenario.base_dir),
        "base": base * scale,
        "yaw": yaw,
        "tool_length": tool,
    }


def _bag_options(args: argparse.Namespace) -> dict:
    """write_bag keywords of --bag-topic, --frame, --stamp, --ros1."""
    from ..io.bags import start_stamp

    return {
        "topic": args.bag_topic,
        "frame_id": args.frame,
        "origin": start_stamp(args.stamp),
        "ros": 1 if args.ros1 else 2,
    }


def _stamped(options: dict) -> str:
    import datetime

    moment = datetime.datetime.fromtimestamp(options["origin"], datetime.UTC)
    return (
        f"stamped from {moment.isoformat(timespec='milliseconds').replace('+00:00', 'Z')}, "
        f"frame {options['frame_id']}"
    )


def _ik_bag(args: argparse.Namespace, trajectory, dmp, where) -> str:
    """A position model's motion as the robot's JointTrajectory: inverse kinematics at every
    sample (tool pointing down; the robot at --base, turned by --yaw, in the model's frame)."""
    import numpy as np

    from .._units import conversion
    from ..io.bags import write_bag
    from ..sim.kinematics import inverse_kinematics, joint_names

    if not dmp.units_ or dmp.units_ == "rad":
        raise ValueError(
            "--robot with --bag: inverse kinematics needs the model's length unit; fit it with --units"
        )
    scale = conversion(dmp.units_, "m")
    arm = _arm(args, scale)
    joints = inverse_kinematics(trajectory.y * scale, units="m", **arm)
    velocities = np.gradient(joints, trajectory.t, axis=0)
    options = _bag_options(args)
    kind = "follow" if args.follow else "joints"
    path = write_bag(
        where,
        trajectory.t,
        joints,
        kind=kind,
        names=joint_names(arm["robot"]),
        velocities=velocities,
        accelerations=np.gradient(velocities, trajectory.t, axis=0),
        **options,
    )
    name = arm["robot"] if isinstance(arm["robot"], str) else arm["robot"].name
    return (
        f"{path} ({_joint_message(kind, options)} of the {name} after inverse kinematics, "
        f"{len(trajectory)} points, {_stamped(options)})"
    )


def _joint_message(kind: str, options: dict) -> str:
    from ..io.bags import FOLLOW_JOINT_TRAJECTORY, JOINT_TRAJECTORY

    msgtype = FOLLOW_JOINT_TRAJECTORY[options["ros"]] if kind == "follow" else JOINT_TRAJECTORY
    topic = options["topic"] or (
        "/bidmp/follow_joint_trajectory/goal" if kind == "follow" else "/bidmp/joint_trajectory"
    )
    return f"{msgtype.replace('/msg/', '/')} on {topic}"


def _rollout_bag(args: argparse.Namespace, trajectory, dmp, poses: bool, where) -> str:
    """``--bag OUT``: the motion as a PoseStamped stream in metres (pose models; position models
    with --orientation, the orientation held), a PointStamped stream (position models without it:
    no orientation is made up), the robot's JointTrajectory after IK (position models with
    --robot), or a JointTrajectory (joint-space models, their joint names); --follow: a
    FollowJointTrajectory goal instead of the JointTrajectory. ROS 2 MCAP or ``--ros1``; written
    at ``where`` (beside --bag's place, :func:`bidmp.io.runs.output_files`)."""
    import numpy as np

    from .._units import conversion
    from ..io.bags import write_bag

    if args.robot_given and not poses and dmp.n_dims_ == 3:
        return _ik_bag(args, trajectory, dmp, where)
    options = _bag_options(args)
    if poses or dmp.n_dims_ == 3:
        if args.follow:
            raise ValueError(
                "--follow writes joint motions: a joint-space model, or --robot for a position model's joints"
            )
        if not dmp.units_:
            raise ValueError(
                "--bag: ROS poses are in metres and this model's length unit is not known; fit it with --units"
            )
        if poses and args.orientation is not None:
            raise ValueError(
                "--orientation is the held orientation of a position model; a pose model has its own"
            )
        held = (
            None
            if poses
            else args.orientation
            if args.orientation is not None
            else dmp.__dict__.get("held_orientation_")
        )
        scale = conversion(dmp.units_, "m")
        values = (
            trajectory.y * scale if not poses else np.hstack([trajectory.y * scale, trajectory.q])
        )
        path = write_bag(where, trajectory.t, values, kind="pose", orientation=held, **options)
        if poses:
            what = "geometry_msgs/PoseStamped"
        elif held is not None:
            source = "given" if args.orientation is not None else "the demonstration's"
            what = (
                f"geometry_msgs/PoseStamped, {source} orientation "
                f"{np.array2string(np.asarray(held), precision=4)} held"
            )
        else:
            what = (
                "geometry_msgs/PointStamped: the model knows no orientation and none is made up (--orientation QX QY "
                "QZ QW holds one)"
            )
        topic = options["topic"] or ("/bidmp/pose" if held is not None or poses else "/bidmp/point")
        return (
            f"{path} ({what} on {topic}, {len(trajectory)} messages, metres, {_stamped(options)})"
        )
    if args.orientation is not None:
        raise ValueError(
            "--orientation is the held orientation of a position model's bag; a joint-space "
            "model's bag holds joints"
        )
    kind = "follow" if args.follow else "joints"
    path = write_bag(
        where,
        trajectory.t,
        trajectory.y,
        kind=kind,
        velocities=trajectory.yd,
        names=list(trajectory.names) or None,
        accelerations=trajectory.ydd,
        **options,
    )
    named = (
        f"joints {', '.join(trajectory.names)}"
        if trajectory.names
        else "joints unnamed: joint1 ..."
    )
    return f"{path} ({_joint_message(kind, options)}, {len(trajectory)} points, {named}, {_stamped(options)})"


def _rollout_extras(args: argparse.Namespace, dmp, poses: bool, default_goal) -> dict:
    """trajectory() keywords from --via and --scene/--avoid (on by default with a scene);
    ``default_goal``: where the motion goes without --goal (the target it is, for the steering)."""
    import numpy as np

    extras = {}
    if args.via:
        width = 7 if poses else dmp.n_dims_
        for index, values in enumerate(args.via):
            if len(values) != 1 + width:
                raise ValueError(
                    f"--via #{index + 1} needs T and {width} coordinates, got {len(values)} numbers"
                )
        extras["via"] = [(values[0], values[1:]) for values in args.via]
    avoid = args.scene is not None if args.avoid is None else args.avoid
    if args.target_label is not None and not avoid:
        raise ValueError(
            "--target-label names the target whose parts the steering leaves out: it needs "
            "--scene (and not --no-avoid)"
        )
    if avoid:
        if args.scene is None:
            raise ValueError("--avoid needs --scene (the scenario whose parts to steer round)")
        if poses or dmp.n_dims_ != 3:
            raise ValueError(
                f"{'--scene' if args.avoid is None else '--avoid'} steers 3-D position models round "
                f"the parts (the tool points down); this model is "
                + ("a pose model" if poses else f"{dmp.n_dims_}-D")
            )
        from ..primitives.avoidance import SceneAvoidance

        scenario, label = scenario_option(args, dmp.units_), args.target_label
        goal = np.asarray(
            default_goal if args.goal is None else args.goal,
            dtype=float,
        )[:3]
        # the goal is a target of the scenario (within its success threshold): its label
        distances = {
            name: float(np.linalg.norm(np.asarray(point, dtype=float)[:3] - goal))
            for name, point in scenario.targets.items()
        }
        nearest = min(distances, key=distances.get) if distances else None
        at = nearest if nearest and distances[nearest] <= scenario.success_threshold else None
        if label is not None and at is not None and label != at:
            raise ValueError(
                f"--target-label {label}, but the goal is target {at}'s position: the steering would "
                f"keep the tool off the parts it must enter"
            )
        label = at if label is None else label
        extras["coupling"] = [SceneAvoidance(scenario.scene, target=label)]
    return extras


def _add_rollout_arguments(rollout) -> None:
    """The arguments of ``bidmp rollout``."""
    rollout.add_argument(
        "model", metavar="MODEL", help="model file (.npz) written by 'bidmp fit' or 'bidmp extend'"
    )
    rollout.add_argument(
        "--goal",
        type=float,
        nargs="+",
        metavar="X",
        help="goal coordinates in the model's units (default: the demonstrated goal)",
    )
    rollout.add_argument(
        "--start",
        type=float,
        nargs="+",
        metavar="X",
        help="start coordinates (default: the demonstrated start)",
    )
    rollout.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="duration of the motion in seconds (temporal scaling; default: the demonstration's)",
    )
    rollout.add_argument(
        "--rate",
        type=float,
        default=None,
        metavar="HZ",
        help="sample rate in Hz (default: the demonstration's)",
    )
    rollout.add_argument(
        "--n-steps",
        type=int,
        default=None,
        help="instead of --rate: this many samples over the same motion",
    )
    rollout.add_argument(
        "--max-speed",
        type=float,
        nargs="+",
        default=None,
        metavar="V",
        help="cap: slow the motion (uniformly) if its speed exceeds V units/s (one V per dimension: per axis/joint)",
    )
    rollout.add_argument(
        "--max-acc",
        type=float,
        nargs="+",
        default=None,
        metavar="A",
        help="cap: slow the motion (uniformly) if its acceleration exceeds A units/s^2 (or one per dimension)",
    )
    rollout.add_argument(
        "--max-jerk",
        type=float,
        nargs="+",
        default=None,
        metavar="J",
        help="cap on the jerk, units/s^3 (or one per dimension)",
    )
    rollout.add_argument(
        "--joint-limits",
        default=None,
        metavar="panda|fr3|iiwa|xarm6|ur5|SCENARIO",
        help="a joint-space model: the robot's per-joint velocity, acceleration and jerk limits (the "
        "Panda's published ones; the iiwa's, the xArm6's and the UR5's published speeds with "
        "assumed acceleration and jerk; or those of the robot a scenario file names)",
    )
    rollout.add_argument(
        "--robot",
        default=None,
        metavar="panda|fr3|iiwa|xarm6|ur5|SCENARIO",
        help="the arm whose inverse kinematics --cartesian-goal and --bag use (default panda; a scenario: "
        "its robot where it stands, with its tool; needs bidmp[sim])",
    )
    rollout.add_argument(
        "--cartesian-goal",
        type=float,
        nargs=3,
        default=None,
        metavar=("X", "Y", "Z"),
        help="a joint-space model of the --robot's joints: roll out to the joints that put its "
        "tool at X Y Z metres in its base frame, tool pointing down (IK from the demonstrated goal's joints)",
    )
    rollout.add_argument(
        "--tool-length",
        type=float,
        default=0.0,
        metavar="M",
        help="with --robot: from the flange to the tool's mouth, metres (default 0)",
    )
    rollout.add_argument(
        "--base",
        type=float,
        nargs=3,
        default=None,
        metavar=("X", "Y", "Z"),
        help="with --robot and --bag: where the robot's base is, in the model's units (default the origin)",
    )
    rollout.add_argument(
        "--yaw",
        type=float,
        default=0.0,
        metavar="DEG",
        help="with --robot and --bag: the base's turn about z, degrees (90: facing +y; default 0)",
    )
    rollout.add_argument(
        "--fastest",
        action="store_true",
        help="with --max-speed/--max-acc: the shortest motion within them, even faster than demonstrated "
        "(without it they are caps that only ever slow a motion)",
    )
    rollout.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT",
        help="trajectory file to write (.csv or .npy; poses: .csv)",
    )
    rollout.add_argument(
        "--skill",
        default=None,
        help="Bi-DMP models: nearest (default), latest or a skill number (0 = plain DMP)",
    )
    rollout.add_argument("--plot", metavar="PNG", help="also write a figure of the rollout")
    rhythm = rollout.add_argument_group("rhythmic models (bidmp fit --periodic)")
    rhythm.add_argument(
        "--cycles", type=float, default=None, metavar="N", help="periods to run (default 1)"
    )
    rhythm.add_argument(
        "--frequency", type=float, default=None, metavar="HZ", help="default: the learned one"
    )
    rhythm.add_argument(
        "--amplitude",
        type=float,
        default=None,
        metavar="A",
        help="scale of the oscillation about the anchor (default 1: as learned)",
    )
    rhythm.add_argument(
        "--anchor",
        type=float,
        nargs="+",
        metavar="X",
        help="the oscillation's centre in the model's units (default: the learned one)",
    )
    rhythm.add_argument(
        "--from-rest",
        action="store_true",
        help="start at rest at the anchor, run the cycles, end at rest there",
    )
    rollout.add_argument(
        "--via",
        type=float,
        nargs="+",
        action="append",
        metavar="T X",
        help="via-point: pass X Y Z (a pose: X Y Z QX QY QZ QW) at T seconds exactly (repeatable)",
    )
    rollout.add_argument(
        "--scene", metavar="FILE|NAME", help="the scenario whose parts the motion is steered round"
    )
    rollout.add_argument(
        "--avoid",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="steer round the scene's parts (SceneAvoidance; default: on with --scene); a motion that "
        "still comes closer than the margin is an error",
    )
    rollout.add_argument(
        "--bag",
        default=None,
        metavar="OUT",
        help="also write the motion to a ROS bag: PoseStamped in metres (a position model: "
        "PointStamped, or PoseStamped with --orientation; a joint-space model: a JointTrajectory "
        "with its joint names), a ROS 2 MCAP folder (--ros1: a .bag file)",
    )
    rollout.add_argument("--ros1", action="store_true", help="with --bag: write a ROS 1 .bag file")
    rollout.add_argument(
        "--frame",
        default="base",
        metavar="FRAME",
        help="with --bag: the header's frame_id (default base)",
    )
    rollout.add_argument(
        "--bag-topic",
        default=None,
        metavar="TOPIC",
        help="with --bag: the topic (default /bidmp/pose, /bidmp/point, /bidmp/joint_trajectory or "
        "/bidmp/follow_joint_trajectory/goal)",
    )
    rollout.add_argument(
        "--stamp",
        default="now",
        metavar="now|SECONDS|ISO",
        help="with --bag: the first header stamp: now (default), seconds since the epoch, or an ISO "
        "8601 time such as 2026-12-03T14:00:00Z",
    )
    rollout.add_argument(
        "--orientation",
        type=float,
        nargs=4,
        default=None,
        metavar=("QX", "QY", "QZ", "QW"),
        help="with --bag, a position model: the tool's orientation, held throughout (PoseStamped); "
        "without it a PointStamped stream (no orientation is made up)",
    )
    rollout.add_argument(
        "--follow",
        action="store_true",
        help="with --bag, joint motions: a control_msgs/FollowJointTrajectory goal (what a ROS 2 "
        "joint trajectory controller takes) instead of a trajectory_msgs/JointTrajectory",
    )
    rollout.add_argument(
        "--target-label",
        default=None,
        metavar="LABEL",
        help="the scene's target the goal is (its parts are not avoided; default: what the tool takes in at the goal)",
    )
    # every option's value when it is not given: a model that acts on only some refuses the rest
    rollout.set_defaults(
        unset_options={
            action.dest: action.default
            for action in rollout._actions
            if action.option_strings and action.dest != "help"
        }
    )
