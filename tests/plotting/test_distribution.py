"""plot_distribution's inputs agree with one another before anything is drawn: a mean given the
wrong way round (2 rows of 60 coordinates beside demonstrations of 2) was an IndexError from
inside matplotlib's loop; a conditioned spread without its motion was drawn nowhere, silently."""

import numpy as np
import pytest

from bidmp.plotting import plot_distribution

pytest.importorskip("matplotlib")

RNG = np.random.default_rng(3)
DEMOS = [np.cumsum(RNG.normal(size=(n, 2)), axis=0) for n in (60, 45)]
MEAN, STD = DEMOS[0], np.full((60, 2), 0.5)


def test_the_plot_is_written(tmp_path):
    path = plot_distribution(
        tmp_path / "d.png", DEMOS, MEAN, STD, conditioned=MEAN + 1.0, conditioned_std=STD / 2
    )
    assert path.stat().st_size > 10_000


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (
            {"mean": np.ascontiguousarray(MEAN.T), "std": np.ascontiguousarray(STD.T)},
            "demonstrations[0]",
        ),
        ({"conditioned": np.zeros((60, 3))}, "conditioned has 3"),
        ({"conditioned": MEAN, "conditioned_std": np.ones((30, 2))}, "conditioned_std"),
        ({"conditioned": MEAN, "conditioned_std": -STD}, "conditioned_std"),
        ({"conditioned_std": STD}, "give conditioned too"),
    ],
)
def test_inputs_that_disagree_are_refused_by_name(tmp_path, options, named):
    args = {"mean": MEAN, "std": STD, **options}
    with pytest.raises(ValueError, match=named.replace("[", r"\[").replace("]", r"\]")):
        plot_distribution(tmp_path / "d.png", DEMOS, **args)
    assert not (tmp_path / "d.png").exists()
