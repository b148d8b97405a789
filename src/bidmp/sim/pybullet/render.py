"""Pictures of the cell by PyBullet's TinyRenderer (headless, no GPU)."""

from __future__ import annotations

import numpy as np

__all__ = []


# -- pictures --------------------------------------------------------------------------
def _render(cell, width: int = 320, height: int = 240, target=None) -> np.ndarray:
    """An RGB image (height, width, 3) of the cell by PyBullet's TinyRenderer (headless)."""
    p = cell.p
    if target is None:  # between the robot and its work, a little above: the whole arm in view
        look = 0.5 * (cell.base + _scene_centre(cell)) * cell.unit + [0.0, 0.0, 0.2]
    else:
        look = np.asarray(target, dtype=float) * cell.unit
    view = p.computeViewMatrixFromYawPitchRoll(look.tolist(), 1.2, cell.yaw - 50.0, -25.0, 0.0, 2,
                                               physicsClientId=cell.client)
    projection = p.computeProjectionMatrixFOV(45.0, width / height, 0.02, 5.0, physicsClientId=cell.client)
    _, _, rgba, _, _ = p.getCameraImage(width, height, view, projection, renderer=p.ER_TINY_RENDERER,
                                        physicsClientId=cell.client)
    return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]


def _scene_centre(cell) -> np.ndarray:
    """The middle of the scene's parts (scene units)."""
    lower, upper = np.min([s.lower for s in cell.scene.solids], axis=0), np.max([s.upper for s in cell.scene.solids], axis=0)
    return 0.5 * (lower + upper)
