"""Pictures of the cell by PyBullet's TinyRenderer (headless, no GPU)."""

from __future__ import annotations

import numpy as np

from ..._checks import as_point, check_int, check_real

__all__ = []

# per side: TinyRenderer allocates width x height buffers (a negative size aborts it)
_MAX_PIXELS = 4096


def _image_size(width, height) -> tuple[int, int]:
    return (
        check_int(width, "width", minimum=8, maximum=_MAX_PIXELS),
        check_int(height, "height", minimum=8, maximum=_MAX_PIXELS),
    )


# -- pictures --------------------------------------------------------------------------
def _render(cell, width: int = 320, height: int = 240, target=None) -> np.ndarray:
    """An RGB image (height, width, 3) of the cell by PyBullet's TinyRenderer (headless)."""
    p = cell.p
    width, height = _image_size(width, height)
    if target is None:  # between the robot and its work, a little above: the whole arm in view
        look = 0.5 * (cell.base + _scene_centre(cell)) * cell.unit + [0.0, 0.0, 0.2]
    else:
        look = as_point(target, 3, "target") * cell.unit
    view = p.computeViewMatrixFromYawPitchRoll(
        look.tolist(), 1.2, cell.yaw - 50.0, -25.0, 0.0, 2, physicsClientId=cell.client
    )
    projection = p.computeProjectionMatrixFOV(
        45.0, width / height, 0.02, 5.0, physicsClientId=cell.client
    )
    _, _, rgba, _, _ = p.getCameraImage(
        width, height, view, projection, renderer=p.ER_TINY_RENDERER, physicsClientId=cell.client
    )
    return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]


def _camera(
    cell, look_m, distance: float, yaw: float, pitch: float, width: int, height: int
) -> np.ndarray:
    p = cell.p
    view = p.computeViewMatrixFromYawPitchRoll(
        np.asarray(look_m, float).tolist(),
        distance,
        yaw,
        pitch,
        0.0,
        2,
        physicsClientId=cell.client,
    )
    projection = p.computeProjectionMatrixFOV(
        45.0, width / height, 0.02, 6.0, physicsClientId=cell.client
    )
    _, _, rgba, _, _ = p.getCameraImage(
        width, height, view, projection, renderer=p.ER_TINY_RENDERER, physicsClientId=cell.client
    )
    return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]


def _keyframe(cell, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
    """A labelled keyframe (2 height, width, 3): above, the whole arm and its work from the side;
    below, a close-up on the tool and the target ``focus`` (scene units); the time written in."""
    width, height = _image_size(width, height)
    t = check_real(t, "t")
    focus_m = as_point(focus, 3, "focus") * cell.unit
    base_m = cell.base * cell.unit
    # The whole arm: between its base and the target, at mid-height of a ~0.9 m arm, from 1.45 m.
    look = 0.5 * (base_m + focus_m) + [0.0, 0.0, 0.3]
    wide = _camera(cell, look, 1.45, cell.yaw - 60.0, -15.0, width, height)
    close = _camera(cell, focus_m + [0.0, 0.0, 0.04], 0.28, cell.yaw - 60.0, -30.0, width, height)
    return _label(
        np.concatenate([wide, close], axis=0),
        [(f"t = {t:.2f} s", 0), ("close-up: tool and target", height)],
    )


def _label(image: np.ndarray, texts) -> np.ndarray:
    """``image`` with each ``(text, top)`` written on a white band at the top-left from ``top``."""
    from PIL import Image, ImageDraw, ImageFont

    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture)
    font = ImageFont.load_default(size=15)
    for text, top in texts:
        box = draw.textbbox((6, top + 4), text, font=font)
        draw.rectangle((box[0] - 3, box[1] - 2, box[2] + 3, box[3] + 2), fill=(255, 255, 255))
        draw.text((6, top + 4), text, fill=(20, 20, 20), font=font)
    return np.asarray(picture)


def _scene_centre(cell) -> np.ndarray:
    """The middle of the scene's parts (scene units)."""
    lower, upper = (
        np.min([s.lower for s in cell.scene.solids], axis=0),
        np.max([s.upper for s in cell.scene.solids], axis=0),
    )
    return 0.5 * (lower + upper)
