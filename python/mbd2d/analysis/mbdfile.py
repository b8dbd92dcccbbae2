"""Export to the plain-text model file read by the standalone ``mbd2d-solve``.

Every analysis can be exported: kinematics, inverse dynamics, dynamics (each method with its
settings), statics and modes, with the optional output columns. The settings are checked exactly as
for a Python run and written as the core takes them, and reals are written with 17
significant digits, so ``mbd2d-solve`` makes the same core call and writes the same CSV as
``res.to_csv`` (docs/mbd-format.md; the format is also described at the top of every file).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

from ..binding.pack import pack, pack_dynamics
from ..binding.tables import NCT, NFT
from ..description.builder import ModelDescription
from ..description.contacts import CONTACT_TYPES
from ..description.drivers import AbsoluteDriver, RelativeAngleDriver, RelativeDistanceDriver
from ..description.forces import PointForce, RotationalSpring, Spring, Torque
from ..description.friction import FRICTION_KIND
from ..description.joints import (Absolute, Cam, Distance, Gear, PinInSlot, PointOnCurve,
                                  PointOnLine, RackPinion, Revolute, RollingDisc, Translational,
                                  Weld)
from ..errors import ModelError
from ..results.files import OUTPUTS, write_text
from ..results.measures import measure_tables
from ..validate import flag, number
from .contacts import check_statics
from .dynamics import dynamics_settings
from .frf import frequency_list, frf_inputs
from .linearize import efforts_rows
from .modes import mode_count
from .sensitivities import check_sens_method, check_positions_only, requested, table
from .settings import (SOLVERS, check_solver, check_span, output_rows, require_determined,
                       solver_code)

FORMAT = 3
#: the analyses a file can hold (check: degrees of freedom and redundancy, as `mbd2d check`)
ANALYSES = ("kinematics", "inverse-dynamics", "dynamics", "statics", "modes", "frf",
            "linearize", "check")
#: every kind code the format holds: (code, type, parameters in the params list)
JOINT_KINDS = [(c.kind, c.type, d) for c, d in [
    (Revolute, "s_i(2) s_j(2)"),
    (Translational, "s_i(2) s_j(2) axis_i(2) axis_j(2)"),
    (Cam, "follower(4), profile (SUB_A: 1 circle, 2 spline, 3 fourier; SUB_B: 1 point, "
          "2 roller, 3 flat)"),
    (Distance, "s_i(2) s_j(2) distance"),
    (PointOnLine, "s_i(2) s_j(2) axis(2) offset"),
    (Weld, "s_i(2) s_j(2) angle"),
    (Gear, "R_i R_j phase pressure_angle c_i(2) c_j(2) a_i(2) a_j(2) (SUB_A carrier body, "
           "SUB_B 1 external, 2 internal)"),
    (RackPinion, "center(2) point(2) axis(2) radius phase"),
    (RollingDisc, "center(2) point(2) axis(2) radius phase"),
    (Absolute, "value (SUB_A: 1 x, 2 y, 3 theta)"),
]] + [(PinInSlot.kind, "revolute-translational", "as point-on-line"),
      (PointOnCurve.kind, "point-on-curve", "as cam")]
DRIVER_KINDS = [(AbsoluteDriver.kind, "absolute driver", "f(t) (SUB_A: 1 x, 2 y, 3 theta)"),
                (RelativeAngleDriver.kind, "relative-angle driver", "f(t)"),
                (RelativeDistanceDriver.kind, "relative-distance driver",
                 "f(t) (SUB_A: its translational joint)")]
FORCE_KINDS = [(Spring.kind, "spring", "s_i(2) s_j(2) stiffness damping length0 f(t)"),
               (Torque.kind, "torque", "f(t)"),
               (PointForce.kind, "point", "s(2) fx(t) fy(t)"),
               (RotationalSpring.kind, "rotational-spring", "stiffness damping angle0 f(t)")]
_LAW = "law k n e mu mu_s threshold (law: 1 linear 2 hertz 3 hunt-crossley " \
       "4 lankarani-nikravesh 5 flores)"
#: the contacts and the joint frictions, force elements after the forces (JOINT: the
#: friction's constraint number, the seventh column of its force line)
ELEMENT_KINDS = [
    (CONTACT_TYPES["circle-line"], "circle-line", f"{_LAW} circle(3) point(2) normal(2)"),
    (CONTACT_TYPES["circle-circle"], "circle-circle", f"{_LAW} circle_i(3) circle_j(3)"),
    (CONTACT_TYPES["circle-in-circle"], "circle-in-circle", f"{_LAW} pin(3) hole(3)"),
    (CONTACT_TYPES["follower-profile"], "follower-profile",
     f"{_LAW} follower code(1) follower(4) profile code(1) profile (as cam)"),
    (FRICTION_KIND, "friction", "mu mu_s model (0 regularized, 1 stick-slip) threshold "
                                "pin_radius; JOINT its joint"),
]


def header() -> str:
    """The comment block at the top of every file: the format and every kind it holds."""
    lines = [
        f"# mbd2d model file, format {FORMAT} (written by `mbd2d export`; run with "
        "`mbd2d-solve FILE OUT.csv`; docs/mbd-format.md)",
        "# Plain text, whitespace separated. Lines starting with '#' are comments.",
        "#   mbd2d 3                      format and version",
        "#   name NAME                    model name",
        "#   analysis A                   kinematics | inverse-dynamics | dynamics | statics "
        "| modes | frf | linearize | check",
        "#   t0, t_end, steps, every      outputs t0 + k (t_end - t0) / steps, k = 0..steps, "
        "every k-th kept",
        "#   tol, maxit, tmin, solver     Newton tolerance, iterations, singular-time "
        "resolution (0 = default); auto | dense | banded",
        "#   positions_only 0|1           kinematics: 1 = positions alone (optional)",
        "#   method, rtol, atol, h, rho_inf, alpha, beta, max_steps   dynamics (0, or -1 for "
        "rho_inf, alpha, beta: default)",
        "#   t                            statics, modes, frf, linearize: the time of loads "
        "and drivers; "
        "check: its time",
        "#   count K, at_q0 0|1           modes: the lowest K; 1 = about q0 as given (also frf, "
        "linearize, whose inputs are the sensitivities block)",
        "#   frequencies NW, then NW reals   frf: the frequencies (Hz); its inputs are the "
        "sensitivities block",
        "#   outputs W ...                optional CSV columns: energy multipliers reactions "
        "efforts (modes: damped, the damped eigenvalues' table instead)",
        "#   gravity GX GY",
        "#   bodies NB, then NB lines     NAME x0 y0 theta0 [mass inertia vx0 vy0 omega0]",
        "#   constraints NC, then NC lines",
        "#        NAME KIND BODY_I BODY_J SUB_A SUB_B OFFSET LENGTH",
        "#        BODY_I, BODY_J: 1-based body numbers, 0 = ground; OFFSET, LENGTH: the",
        "#        constraint's slice of the parameter list (1-based)",
        "#        KIND (joints): " + ", ".join(f"{k} {t}" for k, t, _ in JOINT_KINDS),
        "#        KIND (drivers): " + ", ".join(f"{k} {t}" for k, t, _ in DRIVER_KINDS),
        "#   params NP, then NP reals     per constraint kind:",
    ]
    for k, t, d in JOINT_KINDS + DRIVER_KINDS:
        lines.append(f"#        {k:3d} {t:24s} {d}")
    lines += [
        "#        f(t) = np c0 .. c_{np-1} nh (A omega phase) x nh ns (law t0 t1 h) x ns",
        "#               nt t_1 .. t_nt y_1 .. y_nt",
        "#        (law: 1 cubic, 2 quintic, 3 cycloidal, 4 harmonic, 5 modified sine,",
        "#        6 modified trapezoid)",
        "#   labels NEQ, then NEQ words   NAME.WORD of each row of Phi (multiplier columns)",
        "#   forces NF, then NF lines     NAME KIND BODY_I BODY_J OFFSET LENGTH [JOINT]",
        "#        KIND (forces): " + ", ".join(f"{k} {t}" for k, t, _ in FORCE_KINDS),
        "#        KIND (contacts, joint friction): "
        + ", ".join(f"{k} {t}" for k, t, _ in ELEMENT_KINDS),
        "#   fparams NP, then NP reals    per force kind:",
    ]
    for k, t, d in FORCE_KINDS + ELEMENT_KINDS:
        lines.append(f"#        {k:3d} {t:24s} {d}")
    lines += [
        "#   sensitivities NP, then NP lines   NAME TABLE INDEX (optional): design parameters",
        "#        and their d(COLUMN)/d(NAME) columns; TABLE 1 params, 2 masses (mass, inertia",
        "#        per body), 3 gravity, 4 fparams; INDEX 1-based in that list",
        "#   measures NM, then NM lines   SPEC angle KIND B1 X Y B2 X Y B3 X Y | SPEC "
        "ratio|advantage",
        "#        REF XKIND XINDEX YKIND YINDEX | SPEC conditioning (optional columns: the",
        "#        transmission angle, velocity ratio, mechanical advantage, dead-centre distance)",
        "#   cases NP NV NCASE, then NP lines NAME, NV lines TABLE INDEX, then per case NP + NV",
        "#        reals (optional: a sweep, mbd2d.export_sweep): the swept parameters, the",
        "#        entries each case sets (TABLE as for sensitivities) and their values",
        "#   opens NO, then NO lines      RPAR_INDEX ROW: phases set again from q0 per case",
        "#   end"]
    return "\n".join(lines)


def _r(x: float) -> str:
    return f"{float(x):.17e}"


def _outputs(outputs: Any, analysis: str) -> list[str]:
    if outputs is None:
        return []
    if isinstance(outputs, str):
        outputs = [outputs]
    known = {"modes": ("damped",), "frf": ("reactions",),
             "linearize": ("velocities", "efforts")}.get(analysis, OUTPUTS)
    try:
        words = [str(w) for w in outputs]
    except TypeError:
        raise ModelError(f"outputs must be a list of {', '.join(known)}, got {outputs!r}",
                         "export") from None
    for w in words:
        if w not in known:
            raise ModelError(f"unknown output {w!r}; the optional columns of {analysis} are "
                             f"{', '.join(known) or 'none'}", "export")
    if words and analysis in ("kinematics", "check"):
        raise ModelError(f"{', '.join(words)} need multipliers: export inverse-dynamics, "
                         "dynamics or statics", "export")
    if "energy" in words and analysis == "statics":
        raise ModelError("statics has no energy output", "export")
    return [w for w in known if w in words]


def export(model: ModelDescription, path: str | Path, **settings: Any) -> None:
    """Write a model file for ``mbd2d-solve``; see :meth:`mbd2d.Model.export` (the settings
    as :func:`file_lines` takes them).

    Raises
    ------
    ModelError
        If the model or the settings are invalid (checked as for a Python run).
    """
    lines = file_lines(model, **settings)
    write_text(path, "\n".join(lines + ["end"]) + "\n", "export")


def file_lines(model: ModelDescription, t_end: float | None = None, steps: int | None = None,
               t0: float = 0.0, tol: float | None = None, maxit: int | None = None,
               analysis: str = "kinematics", every: Any = 1, solver: str = "auto",
               method: str | None = None, rtol: Any = None, atol: Any = None, h: Any = None,
               rho_inf: Any = None, alpha: Any = None, beta: Any = None,
               max_steps: Any = None, t: float = 0.0, outputs: Sequence[str] | None = None,
               positions_only: Any = False,
               sensitivities: Sequence[str] | None = None,
               measures: Sequence[str] | None = None,
               measure_refs: bool = False, count: Any = None,
               equilibrium: Any = True, inputs: Sequence[str] | None = None,
               frequencies: Any = None) -> list[str]:
    """The lines of a model file up to its ``end`` line (the header, the model, the analysis
    and its settings, the optional blocks; with measure_refs an angle's points name the
    params entries they come from, for a sweep's cases).

    Raises
    ------
    ModelError
        If the model or the settings are invalid (checked as for a Python run).
    """
    if not isinstance(analysis, str) or analysis not in ANALYSES:
        raise ModelError(f"unknown analysis {analysis!r}; use one of {', '.join(ANALYSES)}",
                         "export")
    words = _outputs(outputs, analysis)
    pos = flag(positions_only, "positions_only", "export")
    if pos and analysis != "kinematics":
        raise ModelError(f"positions_only is a setting of kinematics, not of {analysis}",
                         "export")
    params = requested(model, sensitivities)
    check_positions_only(params, pos)
    if params and analysis in ("check", "modes", "frf", "linearize"):
        raise ModelError(f"{analysis} computes no sensitivities"
                         + (" (its inputs are inputs=[...])" if analysis in ("frf", "linearize")
                            else ""), "export")
    if (inputs is not None and analysis not in ("frf", "linearize")) or \
            (frequencies is not None and analysis != "frf"):
        raise ModelError("inputs are settings of frf and linearize, frequencies of frf, not "
                         f"of {analysis}", "export")
    p = pack(model)
    lines = [header(), f"mbd2d {FORMAT}",
             f"name {model.name.replace(' ', '_') or 'model'}", f"analysis {analysis}"]
    if analysis not in ("statics", "modes", "frf", "linearize", "check"):
        if t_end is None or steps is None:
            raise ModelError(f"{analysis} needs t_end and steps", "export")
        t0, t_end, steps = check_span(t0, t_end, steps)
        output_rows(steps, every)                      # checks every
        lines += [f"t0 {_r(t0)}", f"t_end {_r(t_end)}", f"steps {steps}",
                  f"every {int(every)}"]
    if analysis in ("kinematics", "inverse-dynamics"):
        tol_v, maxit_v = check_solver(tol, maxit if analysis == "kinematics" else None)
        solver_code(solver)
        require_determined(p, model)
        lines += [f"tol {_r(tol_v)}", f"solver {solver}"]
        if analysis == "kinematics":
            lines += [f"maxit {maxit_v}", f"tmin {_r(0.0)}"]
            if pos:
                lines.append("positions_only 1")
    elif analysis == "dynamics":
        st = dynamics_settings(method, rtol, atol, h, rho_inf, alpha, beta, max_steps)
        check_sens_method(params, st.method, "export")
        lines += [f"method {st.method}", f"rtol {_r(st.rtol)}", f"atol {_r(st.atol)}",
                  f"h {_r(st.h)}", f"rho_inf {_r(st.rho_inf)}", f"alpha {_r(st.alpha)}",
                  f"beta {_r(st.beta)}", f"max_steps {st.max_steps}"]
    elif analysis == "check":
        tol_v, _ = check_solver(tol, None)
        lines += [f"tol {_r(tol_v)}", f"t {_r(number(t, 't', 'export'))}"]
    elif analysis == "modes":
        check_statics(model)
        solver_code(solver)
        about_q0 = not flag(equilibrium, "equilibrium", "export")
        lines += [f"t {_r(number(t, 't', 'export'))}", f"count {mode_count(count, p.nq)}",
                  f"at_q0 {int(about_q0)}", f"solver {solver}"]
    elif analysis in ("frf", "linearize"):
        params = frf_inputs(model, inputs, "frequency response" if analysis == "frf"
                            else "linearized system")
        if analysis == "linearize":
            efforts_rows(p, "efforts" in words)
        freq = frequency_list(frequencies) if analysis == "frf" else None
        solver_code(solver)
        about_q0 = not flag(equilibrium, "equilibrium", "export")
        lines += [f"t {_r(number(t, 't', 'export'))}", f"at_q0 {int(about_q0)}",
                  f"solver {solver}"] + ([] if freq is None else _reals("frequencies", freq))
    else:
        lines.append(f"t {_r(number(t, 't', 'export'))}")
    if words:
        lines.append("outputs " + " ".join(words))
    dyn = pack_dynamics(model, p) if analysis not in ("kinematics", "check") else None
    if dyn is not None:
        lines.append(f"gravity {_r(dyn.grav[0])} {_r(dyn.grav[1])}")
    lines.append(f"bodies {p.nb}")
    for i, (name, b) in enumerate(zip(p.body_names, model.bodies)):
        row = f"{name} {_r(b.q0[0])} {_r(b.q0[1])} {_r(b.q0[2])}"
        if dyn is not None:
            row += " " + " ".join(_r(v) for v in (*dyn.bmass[:, i], *dyn.v0[3 * i:3 * i + 3]))
        lines.append(row)
    lines.append(f"constraints {p.nc}")
    for k, name in enumerate(p.constraint_names):
        lines.append(f"{name} " + " ".join(str(int(v)) for v in p.ctab[:NCT - 1, k]))
    lines += _reals("params", p.rpar)
    lines.append(f"labels {len(p.row_labels)}")
    for i in range(0, len(p.row_labels), 6):
        lines.append(" ".join(p.row_labels[i:i + 6]))
    if dyn is not None:
        lines.append(f"forces {dyn.ftab.shape[1]}")
        for k, (name, _, _) in enumerate(model.force_elements()):
            col = dyn.ftab[:, k] if dyn.ftab[NFT - 1, k] else dyn.ftab[:NFT - 1, k]
            lines.append(f"{name} " + " ".join(str(int(v)) for v in col))
        lines += _reals("fparams", dyn.fpar)
    # (the angles' derivatives need the params entries of their points: with sensitivities)
    lines += _measure_lines(model, p, measures, analysis, measure_refs or bool(params))
    if params:
        ptab = table(p, params, dyn)
        lines.append(f"sensitivities {len(params)}")
        lines += [f"{prm.name} {ptab[0, k]} {ptab[1, k]}" for k, prm in enumerate(params)]
    return lines


def _measure_lines(model: ModelDescription, p: Any, specs: Any, analysis: str,
                   moved: bool = False) -> list[str]:
    """The measures block: each spec with the recipe mbd2d-solve evaluates (an angle's
    bodies and points, with moved also the params entries of the points; a ratio's
    reference row and quantities; 1-based)."""
    t = measure_tables(model, p, specs, moved)
    if not t.specs:
        return []
    if analysis in ("statics", "check", "frf", "linearize"):
        raise ModelError(f"measures are columns of a run over time, not of {analysis}",
                         "export")
    words = {2: "ratio", 3: "advantage"}
    lines = [f"measures {len(t.specs)}"]
    for j, spec in enumerate(t.specs):
        if t.kind[j] == 1:
            refs = " " + " ".join(str(int(v)) for v in t.mref[:, :, j].T.ravel()) \
                if moved else ""
            lines.append(f"{spec} angle {t.mint[0, j]} " + " ".join(
                f"{t.mint[1 + k, j]} {_r(t.mpts[0, k, j])} {_r(t.mpts[1, k, j])}"
                for k in range(3)) + refs)
        elif t.kind[j] == 4:
            lines.append(f"{spec} conditioning")
        else:
            lines.append(f"{spec} {words[int(t.kind[j])]} "
                         + " ".join(str(int(v)) for v in t.mint[:, j]))
    return lines


def _reals(key: str, values: Any) -> list[str]:
    n = len(values)
    out = [f"{key} {n}"]
    for i in range(0, n, 4):
        out.append(" ".join(_r(float(v)) for v in values[i:i + 4]))
    return out


__all__ = ["export", "file_lines", "header", "ANALYSES", "FORMAT", "SOLVERS"]
