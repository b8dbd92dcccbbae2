"""The picture gallery of docs/gallery.md: one small mechanism per joint type (and one with
every force element), each run and drawn by mbd2d.

Usage::

    python docs/gallery.py [--out DIR]

writes ``DIR/<name>.png`` (default ``docs/img/gallery``), the README's pictures of the
plotting calls (``plot_mechanism.png``, ``plot_paths.png``, ``plot_timeseries.png``,
``animate.gif``, ``plot_sweep.png``) and, with the default directory, ``docs/gallery.md``.
tests/test_pictures.py runs it into a temporary directory and checks that
every joint type has its picture and that the committed gallery lists the same files.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

CRANK = """
[[body]]
name = "crank"
q0 = [0.5, 0.0, 0.0]
[[joint]]
name = "O"
type = "revolute"
bodies = ["ground", "crank"]
points = [[0, 0], [-0.5, 0]]
[[driver]]
name = "motor"
type = "absolute"
body = "crank"
coordinate = "theta"
f = { poly = [0, 6.283185307179586] }
"""

CAM = """
[model]
name = "cam, {kind} follower"
[[body]]
name = "cam"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "follower"
q0 = [0.0, {y0}, 0.0]
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "cam"]
points = [[0.0, 0.0], [0.0, 0.0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "follower"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[0.0, 1.0], [0.0, 1.0]]
[[joint]]
name = "contact"
type = "cam"
bodies = ["cam", "follower"]
profile = {{ fourier = {{ center = [0.0, 0.0], a = [1.0, 0.25, 0.1], b = [0.0, 0.05] }} }}
follower = {follower}
[[driver]]
name = "motor"
type = "absolute"
body = "cam"
coordinate = "theta"
f = {{ poly = [0.0, 6.283185307179586] }}
"""

#: name -> (joint type shown, caption, TOML text or example file, options)
MODELS: dict[str, tuple[str, str, str, dict[str, Any]]] = {
    "revolute": ("revolute", "Pins between links, hatched pivots on ground (a Grashof "
                 "crank-rocker with the path of a coupler point).", "@fourbar_grashof.toml",
                 {"trace": [("coupler", (0.0, 1.0))]}),
    "translational": ("translational", "A slider block between hatched rails (offset "
                      "slider-crank).", "@slider_crank.toml", {}),
    "cam-roller": ("cam", "A Fourier cam with a roller follower on a vertical guide; the "
                   "black dot is the contact point.",
                   CAM.format(kind="roller", y0=1.5,
                              follower="{ roller = { center = [0.0, 0.0], radius = 0.25 } }"),
                   {}),
    "cam-flat": ("cam", "The same cam with a flat-faced follower.",
                 CAM.format(kind="flat-faced", y0=1.3,
                            follower="{ flat = { point = [0.0, 0.0], normal = [0.0, -1.0] } }"),
                 {}),
    "cam-knife": ("cam", "The same cam with a knife-edge follower.",
                  CAM.format(kind="knife-edge", y0=1.3, follower="{ point = [0.0, 0.0] }"),
                  {}),
    "point-on-curve": ("point-on-curve", "A pin in a curved slot: the coupler's end runs in "
                       "a circular slot fixed to ground.", """
[model]
name = "pin in a curved slot"
""" + CRANK + """
[[body]]
name = "link"
q0 = [1.78, 0.976, 0.896]
[[joint]]
name = "A"
type = "revolute"
bodies = ["crank", "link"]
points = [[0.5, 0], [-1.25, 0]]
[[joint]]
name = "slot"
type = "point-on-curve"
bodies = ["ground", "link"]
curve = { circle = { center = [3.0, 0.0], radius = 2.0 } }
point = [1.25, 0.0]
""", {}),
    "distance": ("distance", "A massless link of fixed length (a thin rod between two "
                 "pins) in place of the four-bar's coupler.", """
[model]
name = "distance constraint"
""" + CRANK + """
[[body]]
name = "rocker"
q0 = [3.25, 1.2, -1.77]
[[joint]]
name = "O4"
type = "revolute"
bodies = ["rocker", "ground"]
points = [[1.25, 0.0], [3.0, 0.0]]
[[joint]]
name = "rod"
type = "distance"
bodies = ["crank", "rocker"]
points = [[0.5, 0.0], [-1.25, 0.0]]
distance = 3.5
""", {}),
    "point-on-line": ("point-on-line", "A point on a line: the rod's end stays on a rail "
                      "(a slider-crank without a slider body).", """
[model]
name = "point on a line"
""" + CRANK + """
[[body]]
name = "rod"
q0 = [2.5, 0.25, 0.17]
[[joint]]
name = "A"
type = "revolute"
bodies = ["crank", "rod"]
points = [[0.5, 0], [-1.5, 0]]
[[joint]]
name = "rail"
type = "point-on-line"
bodies = ["ground", "rod"]
points = [[0, 0.5], [1.5, 0]]
axis = [1, 0]
""", {}),
    "revolute-translational": ("revolute-translational", "A pin in a straight slot: the "
                               "Scotch yoke (the crank pin drives the yoke's slot).", """
[model]
name = "Scotch yoke"
""" + CRANK + """
[[body]]
name = "yoke"
q0 = [1.0, 0.0, 0.0]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "yoke"]
points = [[0.0, 0.0], [0.0, 0.0]]
axes = [[1.0, 0.0], [1.0, 0.0]]
[[joint]]
name = "slot"
type = "revolute-translational"
bodies = ["yoke", "crank"]
points = [[0.0, 0.0], [0.5, 0.0]]
axis = [0.0, 1.0]
""", {}),
    "weld": ("weld", "A plate welded (square) to the crank's end.", """
[model]
name = "weld"
""" + CRANK + """
[[body]]
name = "plate"
q0 = [1.0, 0.2, 0.3]
[[joint]]
name = "W"
type = "weld"
bodies = ["crank", "plate"]
points = [[0.5, 0], [0, -0.2]]
angle = 0.3
""", {}),
    "gear": ("gear", "An external gear pair on ground pivots: pitch circles (dash-dot) "
             "with teeth and a mark that shows the turning.", """
[model]
name = "gear pair"
[[body]]
name = "pinion"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "wheel"
q0 = [2.5, 0.0, 0.0]
[[joint]]
name = "P1"
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "P2"
type = "revolute"
bodies = ["ground", "wheel"]
points = [[2.5, 0], [0, 0]]
[[joint]]
name = "mesh"
type = "gear"
bodies = ["pinion", "wheel"]
radii = [1.0, 1.5]
[[driver]]
name = "motor"
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0, 1.0] }
""", {}),
    "gear-internal": ("gear", "An internal gear: a pinion inside a ring gear (teeth "
                      "inward).", """
[model]
name = "internal gear"
[[body]]
name = "ring"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "pinion"
q0 = [1.2, 0.0, 0.0]
[[joint]]
name = "R"
type = "revolute"
bodies = ["ground", "ring"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "P"
type = "revolute"
bodies = ["ground", "pinion"]
points = [[1.2, 0], [0, 0]]
[[joint]]
name = "mesh"
type = "gear"
bodies = ["pinion", "ring"]
radii = [0.8, 2.0]
internal = true
[[driver]]
name = "motor"
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { poly = [0, 2.0] }
""", {}),
    "rack-pinion": ("rack-pinion", "A pinion driving a rack (teeth toward the pinion) that "
                    "slides between rails.", """
[model]
name = "rack and pinion"
[[body]]
name = "pinion"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "rack"
q0 = [0.0, -1.0, 0.0]
[[joint]]
name = "P"
type = "revolute"
bodies = ["ground", "pinion"]
points = [[0, 0], [0, 0]]
[[joint]]
name = "guide"
type = "translational"
bodies = ["ground", "rack"]
points = [[0.0, -1.0], [0.0, 0.0]]
axes = [[1.0, 0.0], [1.0, 0.0]]
[[joint]]
name = "teeth"
type = "rack-pinion"
bodies = ["pinion", "rack"]
center = [0.0, 0.0]
point = [0.0, 0.0]
axis = [1.0, 0.0]
radius = 1.0
[[driver]]
name = "motor"
type = "absolute"
body = "pinion"
coordinate = "theta"
f = { harmonic = [{ amplitude = 1.5, omega = 6.283185307179586 }] }
""", {}),
    "rolling-disc": ("rolling-disc", "A disc rolling without slip on a line fixed to "
                     "ground (its spoke shows the turning).", """
[model]
name = "rolling disc"
[[body]]
name = "disc"
q0 = [0.0, 0.5, 0.0]
[[joint]]
name = "road"
type = "rolling-disc"
bodies = ["disc", "ground"]
center = [0.0, 0.0]
point = [0.0, 0.0]
axis = [1.0, 0.0]
radius = 0.5
[[driver]]
name = "push"
type = "absolute"
body = "disc"
coordinate = "x"
f = { poly = [0.0, 2.0] }
""", {}),
    "absolute": ("absolute", "Fixed coordinates: the bar's centre is held by absolute x "
                 "and y constraints (short hatched walls) while its angle is driven.", """
[model]
name = "absolute constraints"
[[body]]
name = "bar"
q0 = [0.0, 0.0, 0.0]
[[body]]
name = "arm"
q0 = [1.5, 0.0, 0.0]
[[joint]]
name = "hold_x"
type = "absolute"
body = "bar"
coordinate = "x"
[[joint]]
name = "hold_y"
type = "absolute"
body = "bar"
coordinate = "y"
[[joint]]
name = "A"
type = "revolute"
bodies = ["bar", "arm"]
points = [[0.75, 0.0], [-0.75, 0.0]]
[[joint]]
name = "level"
type = "absolute"
body = "arm"
coordinate = "theta"
[[driver]]
name = "turn"
type = "absolute"
body = "bar"
coordinate = "theta"
f = { harmonic = [{ amplitude = 0.8, omega = 6.283185307179586 }] }
""", {}),
    "forces": ("forces", "Force elements: a spring (zigzag), a rotational spring (spiral), "
               "an applied torque (curved arrow) and point force (orange arrow), with the "
               "joints' reactions (purple arrows) from the inverse dynamics.", """
[model]
name = "force elements"
gravity = [0.0, -9.81]
[[body]]
name = "bar"
q0 = [0.5, 0.0, 0.0]
mass = 1.0
inertia = 0.0833
[[body]]
name = "arm"
q0 = [1.0, -0.5, -1.5708]
mass = 0.5
inertia = 0.04
[[joint]]
name = "pivot"
type = "revolute"
bodies = ["ground", "bar"]
points = [[0.0, 0.0], [-0.5, 0.0]]
[[joint]]
name = "elbow"
type = "revolute"
bodies = ["bar", "arm"]
points = [[0.5, 0.0], [-0.5, 0.0]]
[[driver]]
name = "motor"
type = "absolute"
body = "bar"
coordinate = "theta"
f = { harmonic = [{ amplitude = 0.4, omega = 6.283185307179586 }] }
[[driver]]
name = "wrist"
type = "relative-angle"
bodies = ["bar", "arm"]
f = { poly = [-1.5708] }
[[force]]
name = "spring"
type = "spring"
bodies = ["ground", "arm"]
points = [[1.6, 0.6], [0.5, 0.0]]
stiffness = 50.0
length0 = 0.8
[[force]]
name = "torsion"
type = "rotational-spring"
bodies = ["ground", "bar"]
stiffness = 5.0
[[force]]
name = "twist"
type = "torque"
body = "arm"
f = 2.0
[[force]]
name = "push"
type = "point"
body = "arm"
point = [0.5, 0.0]
fx = -8.0
""", {"forces": True, "times": [0.1]}),
}


def run(name: str) -> Any:
    """The result of a gallery model (one crank turn, 60 steps)."""
    import mbd2d

    _, _, text, _ = MODELS[name]
    model = mbd2d.load(ROOT / "examples" / text[1:]) if text.startswith("@") \
        else mbd2d.loads(text, source=f"gallery {name}")
    return model.kinematics(t_end=1.0, steps=60)


def picture(name: str, path: Path, dpi: int = 60) -> str:
    """Draw one gallery picture."""
    from mbd2d.plots import plot_mechanism, save_figure
    from mbd2d.plots.canvas import new_figure

    _, caption, _, opts = MODELS[name]
    res = run(name)
    ax = new_figure((5.0, 4.0)).add_subplot()
    plot_mechanism(res, ax=ax, times=opts.get("times", [0.0, 0.3, 0.6]),
                   trace=opts.get("trace"), forces=opts.get("forces", False),
                   title=f"{name}: {res.model.name}")
    return save_figure(ax, path, dpi=dpi)


#: the pictures of the README's plotting section: name -> what draws it
README_PICTURES = ("plot_mechanism", "plot_paths", "plot_timeseries", "animate", "plot_sweep")


def readme_pictures(out: Path) -> list[str]:
    """The README's pictures: the crank-rocker drawn by each plotting call."""
    import mbd2d
    from mbd2d.plots import save_figure

    res = mbd2d.load(ROOT / "examples" / "fourbar_masses.toml").kinematics(t_end=1.0,
                                                                             steps=120)
    trace = [("coupler", (0.0, 1.0))]
    done = [save_figure(mbd2d.plot_mechanism(res, trace=trace), out / "plot_mechanism.png",
                        dpi=60),
            save_figure(mbd2d.plot_paths(res, trace + [("coupler", (1.75, 0.0))]),
                        out / "plot_paths.png", dpi=60),
            save_figure(mbd2d.plot_timeseries(res, kind="forces"), out / "plot_timeseries.png",
                        dpi=60)]
    done.append(res.animate(out / "animate.gif", fps=12, trace=trace, size=(4.8, 3.8),
                            dpi=60))
    import numpy as np

    grashof = mbd2d.load(ROOT / "examples" / "fourbar_grashof.toml")
    ds = mbd2d.sweep(grashof, {"joint.O4.points.1.0": np.linspace(2.0, 6.0, 41)}, t_end=1.0,
                     steps=180, measures=["transmission_angle:B"], workers=1)
    done.append(save_figure(mbd2d.plot_sweep(ds), out / "plot_sweep.png", dpi=60))
    return done


def markdown(names: list[str]) -> str:
    """docs/gallery.md."""
    lines = ["# Gallery: how each element is drawn", "",
             "Generated by `python docs/gallery.py` (tests/test_pictures.py runs it and checks "
             "that every joint type has its picture). Each picture shows three snapshots "
             "(t = 0, 0.3, 0.6 s of a one-second run), earlier ones lighter; the drawing of "
             "each element lives in `python/mbd2d/plots/elements.py`.", ""]
    for name in names:
        joint, caption, _, _ = MODELS[name]
        lines += [f"## {name} (`{joint}`)", "", caption, "",
                  f"![{name}](img/gallery/{name}.png)", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE / "img" / "gallery",
                    help="directory for the pictures (default docs/img/gallery)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    names = list(MODELS)
    for name in names:
        print(picture(name, args.out / f"{name}.png"))
    for p in readme_pictures(args.out):
        print(p)
    if args.out.resolve() == (HERE / "img" / "gallery").resolve():
        (HERE / "gallery.md").write_text(markdown(names))
        print(HERE / "gallery.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
