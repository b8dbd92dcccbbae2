"""Cost of pictures of large models: the driven N-four-bar's snapshot picture (6 snapshots,
drawn and saved as PNG) and its 21-frame GIF, with the parts of one look drawn as one
matplotlib artist (python/mbd2d/plots/batch.py) against one artist per part (the scene's
batching switched off in the same run), CPU time.

    python bench/pictures.py [--quick]
"""
from __future__ import annotations

import argparse
import io
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT / "examples") not in sys.path:
    sys.path.insert(0, str(ROOT / "examples"))

import nfourbar  # noqa: E402

import mbd2d.plots.scene as scene_module  # noqa: E402
from mbd2d.plots import plot_mechanism  # noqa: E402

SIZES = (100, 300, 1000)
ALONE_SIZES = (100, 300)       # one artist per part: 38 s for the picture at N = 1000


def cpu(fn: Callable[[], Any]) -> tuple[float, Any]:
    """CPU seconds of one call, and what it returned."""
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def picture(res: Any) -> int:
    """Draw and save the snapshot picture; the number of artists on its Axes."""
    ax = plot_mechanism(res)
    ax.figure.savefig(io.BytesIO(), format="png")
    return len(ax.get_children())


def gif(res: Any) -> None:
    res.animate(fps=40, max_frames=21)


def measure(n: int, batched: bool) -> dict:
    """The picture's and the GIF's CPU seconds for the N-four-bar of n loops."""
    res = nfourbar.build(n).kinematics(0.5, 20)
    saved = scene_module.BATCH_MIN
    try:
        if not batched:
            scene_module.BATCH_MIN = 10**9
        picture_s, artists = cpu(lambda: picture(res))
        return {"n": n, "batched": batched, "artists": artists, "picture_s": picture_s,
                "gif_s": cpu(lambda: gif(res))[0]}
    finally:
        scene_module.BATCH_MIN = saved


def study(quick: bool = False) -> dict:
    """Every size batched, the smaller ones also one artist per part; the ratios."""
    sizes = SIZES[:1] if quick else SIZES
    alone = ALONE_SIZES[:1] if quick else ALONE_SIZES
    warm = nfourbar.build(2).kinematics(0.5, 2)      # imports, fonts and caches: not timed
    picture(warm)
    gif(warm)
    rows = [measure(n, True) for n in sizes] + [measure(n, False) for n in alone]
    for r in rows:
        if not r["batched"]:
            b = next(x for x in rows if x["batched"] and x["n"] == r["n"])
            b["picture_ratio"] = r["picture_s"] / b["picture_s"]
            b["gif_ratio"] = r["gif_s"] / b["gif_s"]
    return {"model": "driven N-four-bar, 0.5 s, 21 rows", "picture": "6 snapshots, PNG",
            "gif": "21 frames, 512 x 400", "rows": rows}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    print(json.dumps(study(ap.parse_args().quick), indent=1))


if __name__ == "__main__":
    main()
