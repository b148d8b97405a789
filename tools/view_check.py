"""Render a bidmp 3-D viewer file in headless Chromium and check the picture is not blank
(``make view-check``).

    python tools/view_check.py VIEW_HTML [--screenshot PNG]

Chromium (Debian's package ``chromium``: ``apt install chromium``) draws the page with its
software WebGL (SwiftShader), offline: the file must carry plotly.js itself. The check reads the
screenshot: inside the 3-D scene's area, the share of pixels that are not the background, and
whether the layers' own colours are there (the Bi-DMP and DMP rollouts, the robot's links and
joints; with ``--expect-failing``, the warning colour of a motion that breaks the contract). Exit 0
when every check passes, 1 otherwise, 2 when Chromium is missing.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

# Flags of a headless Chromium on a machine without a network or a GPU: no background
# connections (refused here, many at a time), every host name unresolvable (so that the page is
# shown to work offline on a machine with a network too), software WebGL, a fresh profile.
FLAGS = [
    "--headless",
    "--host-resolver-rules=MAP * ~NOTFOUND",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1280,900",
    "--virtual-time-budget=15000",
]
COLOURS = {
    "bidmp rollouts": (214, 39, 40),
    "dmp rollouts": (31, 119, 180),
    "robot links": (154, 154, 154),
    "robot joints": (255, 140, 0),
}
WARNING = {"failing motions": (255, 192, 0)}  # bidmp.plotting.viewer.WARNING: with --expect-failing


def screenshot(page: Path, png: Path) -> None:
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        print(
            "view-check: Chromium is not installed (Debian: apt install chromium)", file=sys.stderr
        )
        raise SystemExit(2)
    with tempfile.TemporaryDirectory() as profile:
        subprocess.run(
            [
                chromium,
                *FLAGS,
                f"--user-data-dir={profile}",
                f"--screenshot={png}",
                page.resolve().as_uri(),
            ],
            check=True,
            capture_output=True,
            timeout=180,
        )


def checks(png: Path) -> dict:
    from PIL import Image

    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    height, width, _ = image.shape
    scene = image[
        int(0.06 * height) : int(0.78 * height), : int(0.82 * width)
    ]  # not the legend, title or slider
    background = np.array([229, 236, 246])  # plotly's 3-D axes' pale blue; white around them
    plain = (np.abs(scene - background).sum(axis=2) < 12) | (scene.min(axis=2) > 245)
    found = {
        name: int((np.abs(scene - np.array(rgb)).sum(axis=2) < 40).sum())
        for name, rgb in {**COLOURS, **WARNING}.items()
    }
    return {"size": (width, height), "drawn_share": float(1.0 - plain.mean()), "pixels_of": found}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", type=Path)
    parser.add_argument("--screenshot", type=Path, default=None)
    parser.add_argument(
        "--expect-failing",
        action="store_true",
        help="the page shows a motion that breaks the contract: its warning colour must be drawn",
    )
    args = parser.parse_args()
    if not args.page.is_file():
        print(f"view-check: {args.page}: no such file", file=sys.stderr)
        return 1
    text = args.page.read_text(errors="replace")
    # No script fetched from elsewhere; plotly.js itself inside (its text mentions a CDN for map
    # data, which a 3-D scatter never loads).
    offline = '<script src="http' not in text and "plotly.js v" in text
    png = args.screenshot or args.page.with_suffix(".png")
    screenshot(args.page, png)
    result = checks(png)
    needed = {**COLOURS, **(WARNING if args.expect_failing else {})}
    ok = (
        offline
        and result["drawn_share"] >= 0.03
        and all(result["pixels_of"][name] >= 30 for name in needed)
    )
    print(
        f"view-check {'passed' if ok else 'FAILED'}: {png} {result['size'][0]}x{result['size'][1]}, "
        f"{100 * result['drawn_share']:.1f} % of the scene's area drawn, offline (no CDN script): {offline}; "
        + ", ".join(f"{name}: {count} px" for name, count in result["pixels_of"].items())
    )
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
