"""extend_demonstration: the whole chain 1D-SEG → piece → G-PRM → complete demonstration."""

import numpy as np
import pytest

import bidmp
from bidmp import extend_demonstration
from bidmp.demonstrations import lasa, minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET
from bidmp.extension import RoadmapOptions


@pytest.fixture(scope="module")
def battery():
    return minimum_jerk(BATTERY_APPROACH_VIA, 200)


def step_lengths(y):
    return np.linalg.norm(np.diff(y, axis=0), axis=1)


def test_complete_demonstration_shape_ends_and_parts(battery):
    result = extend_demonstration(battery, BATTERY_EXTENSION_TARGET, seed=0, approach="paper")
    assert result.complete.shape == battery.shape
    assert np.array_equal(result.complete[0], battery[0])
    assert np.array_equal(result.complete[-1], BATTERY_EXTENSION_TARGET)
    np.testing.assert_array_equal(
        result.tra_imi, battery[result.piece.start : result.piece.end + 1]
    )
    assert result.seg_index == result.piece.start
    assert np.array_equal(result.tra_gen[0], battery[result.seg_index])
    assert np.array_equal(result.tra_gen[-1], BATTERY_EXTENSION_TARGET)
    assert result.similarity_history.shape == (10,)
    # The battery approach is cut at the end of the lateral move; the descent is imitated.
    np.testing.assert_allclose(battery[result.seg_index], [0.0, 0.0, 40.0], atol=2.0)


@pytest.mark.parametrize("name, offset", [("Sshape", [15.0, -10.0]), ("WShape", [-8.0, 12.0])])
@pytest.mark.parametrize("approach", ["paper", "keep"])
def test_junction_is_continuous_in_position_and_speed(name, offset, approach):
    y = lasa(name)[0]
    result = extend_demonstration(y, y[-1] + offset, seed=2, approach=approach)
    complete = result.complete
    # The complete demonstration passes through seg, where the prefix hands over to Tra_gen.
    seg = y[result.seg_index]
    junction = int(np.argmin(np.linalg.norm(complete - seg, axis=1)))
    assert np.linalg.norm(complete[junction] - seg) < 2 * step_lengths(complete).max()
    speeds = step_lengths(complete)
    before, after = speeds[junction - 3 : junction].mean(), speeds[junction : junction + 3].mean()
    assert after == pytest.approx(before, rel=0.15)
    # No jumps anywhere: neighbouring steps differ smoothly, and it ends at rest.
    assert np.max(np.abs(np.diff(speeds))) < 0.1 * speeds.max()
    if approach == "paper":
        assert speeds[-1] < 0.05 * speeds.max()
    else:  # the kept approach arrives as the demonstration does
        assert speeds[-1] == pytest.approx(step_lengths(y)[-1], rel=1e-9)


def test_same_seed_same_extension_and_options_pass_through(battery):
    first = extend_demonstration(battery, BATTERY_EXTENSION_TARGET, seed=4)
    again = extend_demonstration(battery, BATTERY_EXTENSION_TARGET, seed=4)
    assert np.array_equal(first.complete, again.complete)
    fewer = extend_demonstration(
        battery,
        BATTERY_EXTENSION_TARGET,
        seed=4,
        roadmap=RoadmapOptions(n_iter=3, n_samples=100),
        eps_frac=0.2,
    )
    assert fewer.similarity_history.shape == (3,)
    with pytest.raises(TypeError, match="unexpected keyword argument 'n_iter'"):
        extend_demonstration(battery, BATTERY_EXTENSION_TARGET, n_iter=3)
    with pytest.raises(
        TypeError, match="roadmap must be a bidmp.extension.RoadmapOptions.*got dict"
    ):
        extend_demonstration(battery, BATTERY_EXTENSION_TARGET, roadmap={"n_iter": 3})


def test_target_at_seg_skips_gprm(battery):
    result = extend_demonstration(
        battery, battery[-1], seed=0, approach="paper"
    )  # the demonstrated end: nearest piece end
    assert np.array_equal(result.complete[-1], battery[-1])
    seg_target = extend_demonstration(
        battery, battery[0], seed=0, approach="paper"
    )  # coincides with seg of piece 0
    assert seg_target.similarity_history.size == 0
    assert np.array_equal(seg_target.complete[-1], battery[0])


@pytest.mark.parametrize(
    "y, target, match",
    [
        (minimum_jerk(BATTERY_APPROACH_VIA, 200), [1.0, 2.0], "new_target must have 3"),
        (minimum_jerk(BATTERY_APPROACH_VIA, 200), [1.0, np.nan, 0.0], "NaN"),
        (minimum_jerk(BATTERY_APPROACH_VIA, 5), [1.0, 2.0, 0.0], "at least 10 points"),
        (np.zeros((50, 3)), [1.0, 2.0, 0.0], "identical"),
    ],
)
def test_bad_input(y, target, match):
    with pytest.raises(ValueError, match=match):
        extend_demonstration(y, target)


def test_the_battery_extension_with_defaults_reaches_its_target(battery):
    # How long it takes is benchmarks/bench_extension.py's (no clock in the tests).
    extension = extend_demonstration(battery, BATTERY_EXTENSION_TARGET, seed=0)
    np.testing.assert_allclose(extension.complete[-1], BATTERY_EXTENSION_TARGET, atol=1e-9)


def test_options_are_listed_in_the_signature_and_a_scenario_names_the_same():
    """Structure guard: the signature spells every option (no ``**kwargs``); a scenario file's
    flat "extension" keys are the segmentation's, the approach and G-PRM's options (the classic
    PRM's padding is no extension option), and they turn into the same call."""
    import dataclasses
    import inspect

    from bidmp.extension import check_extension_options
    from bidmp.tasks.scenarios import _EXTENSION_KEYS

    signature = inspect.signature(extend_demonstration).parameters
    assert (
        signature["eps_frac"].default
        == inspect.signature(bidmp.segment).parameters["eps_frac"].default
    )
    assert not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in signature.values())
    fields = {field.name for field in dataclasses.fields(RoadmapOptions)}
    assert _EXTENSION_KEYS == {"eps_frac", "method", "approach"} | (fields - {"padding"})
    arguments = check_extension_options(eps_frac=0.2, n_iter=3, approach="paper")
    assert arguments == {
        "eps_frac": 0.2,
        "method": "persistence",
        "approach": "paper",
        "roadmap": RoadmapOptions(n_iter=3),
    }
    assert set(arguments) <= set(signature)
    with pytest.raises(TypeError, match="unknown extension option 'n_iterations'"):
        check_extension_options(n_iterations=3)


@pytest.mark.parametrize("seed", range(6))
def test_a_transfer_template_turned_for_a_turned_approach(seed):
    """The template of a transfer that joins an approach turned by R: each step keeps its length,
    the first keeps its direction and the last takes R's, each within the turn the step's own
    share of the arc allows (the turn grows with the arc length, from none to R)."""
    from scipy.spatial.transform import Rotation

    from bidmp.extension.extend import _turned

    rng = np.random.default_rng(seed)
    piece = np.cumsum(rng.uniform(-5.0, 5.0, (int(rng.integers(5, 60)), 3)), axis=0)
    turn = Rotation.from_rotvec(rng.uniform(-0.6, 0.6, 3))
    turned = _turned(piece, turn.as_matrix())
    steps, new = np.diff(piece, axis=0), np.diff(turned, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    np.testing.assert_allclose(np.linalg.norm(new, axis=1), lengths, rtol=1e-12)
    assert np.array_equal(turned[0], piece[0])

    def angle(a, b):
        return np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))

    share = lengths / lengths.sum()
    assert angle(new[0], steps[0]) <= turn.magnitude() * share[0] / 2 + 1e-9
    assert angle(new[-1], turn.apply(steps[-1])) <= turn.magnitude() * share[-1] / 2 + 1e-9
