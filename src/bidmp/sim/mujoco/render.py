"""Pictures of the MuJoCo cell by MuJoCo's own renderer, off-screen (EGL unless ``MUJOCO_GL``
names another); the cameras and labels of the PyBullet backend's pictures."""

from __future__ import annotations

import numpy as np

from ..._checks import as_point, check_real
from ..pybullet.render import _image_size, _label, _scene_centre

__all__ = []


def _camera(cell, look_m, distance: float, yaw: float, pitch: float, width: int, height: int):
    """The world seen from ``distance`` (m) at ``yaw``, ``pitch`` (degrees, PyBullet's
    convention: yaw 0 looks along +y) towards ``look_m`` (m)."""
    mujoco = cell.mj
    renderer = getattr(cell, "_renderer", None)
    if renderer is None or (renderer.width, renderer.height) != (width, height):
        if renderer is not None:
            renderer.close()
        cell.m.vis.global_.offwidth = max(int(cell.m.vis.global_.offwidth), width)
        cell.m.vis.global_.offheight = max(int(cell.m.vis.global_.offheight), height)
        try:
            renderer = mujoco.Renderer(cell.m, height, width)
        except Exception as exc:  # no OpenGL context here (no EGL, no display)
            from ..backend import SimError

            raise SimError(
                f"MuJoCo cannot draw here ({type(exc).__name__}: set MUJOCO_GL to egl or osmesa, "
                f"or run without pictures)"
            ) from None
        cell._renderer = renderer
    camera = mujoco.MjvCamera()
    camera.lookat[:] = np.asarray(look_m, dtype=float)
    camera.distance = distance
    camera.azimuth = yaw - 90.0
    camera.elevation = pitch
    renderer.update_scene(cell.d, camera)
    return np.array(renderer.render(), dtype=np.uint8)


def _render(cell, width: int = 320, height: int = 240, target=None) -> np.ndarray:
    """An RGB image (height, width, 3) of the cell."""
    width, height = _image_size(width, height)
    if target is None:
        look = 0.5 * (cell.base + _scene_centre(cell)) * cell.unit + [0.0, 0.0, 0.2]
    else:
        look = as_point(target, 3, "target") * cell.unit
    return _camera(cell, look, 1.2, cell.yaw - 50.0, -25.0, width, height)


def _keyframe(cell, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
    """A labelled keyframe (2 height, width, 3): the whole arm above, the close-up below."""
    width, height = _image_size(width, height)
    t = check_real(t, "t")
    focus_m = as_point(focus, 3, "focus") * cell.unit
    base_m = cell.base * cell.unit
    look = 0.5 * (base_m + focus_m) + [0.0, 0.0, 0.3]
    wide = _camera(cell, look, 1.45, cell.yaw - 60.0, -15.0, width, height)
    close = _camera(cell, focus_m + [0.0, 0.0, 0.04], 0.28, cell.yaw - 60.0, -30.0, width, height)
    return _label(
        np.concatenate([wide, close], axis=0),
        [(f"t = {t:.2f} s", 0), ("close-up: tool and target", height)],
    )
