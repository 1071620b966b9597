"""``cosim validate [CASE ...]``: run validation cases and print measured values next to their references.

Human output is a table (case, quantity, measured, reference, error, tolerance, pass, wall time) plus one PNG per
case run; ``--json`` prints a machine-readable document instead (the contract for outside checks):
``{"passed": bool, "cases": [{"case", "passed", "wall_time_s", "parameters", "metrics": [...], <raw values>}]}``
with the raw values of each case (slosh ``frequency_hz``; hydrostatic ``z``, ``pressure``, ``leaked``;
dam-break ``a``, ``t``, ``front``, ``tip_height``, ``gate_lift`` (m; null without a gate), ``lauber_hager_speed``
(m/s), ``reference_points`` (each ``T``, ``Z_reference``, ``Z``, ``error``, ``time_lead``);
slosh-plant ``omega1_sph``, ``omega1_model`` (rad/s), ``hinge_height_sph``, ``hinge_height_model`` (m above the inner
floor), ``damping_ratio_sph``, ``pivots``, ``signed_amplitudes``, ``identified_model``, ``t``, ``sigma``; outflow
``coefficient``, ``rehbock``, ``discharge`` (m^2/s), ``head`` (m), ``t``, ``passed_area``, ``head_series``). A failed
validation is reported, not hidden; with ``--strict`` it also makes the exit status 1.
"""

from __future__ import annotations

import argparse
import json
import sys
from enum import Enum
from pathlib import Path

from typing import TYPE_CHECKING

from cosim.atomic_files import atomic_path, check_output_folder
from cosim.errors import InputError
from cosim.fluid.config import FluidConfig, PressureSolver
from cosim.validation import CASES, DEFAULT_CASES
from declared_settings.setting import declared

if TYPE_CHECKING:
    from cosim.validation.common import CaseResult

DEFAULT_OUT = Path("recordings") / "validate"
# The FluidConfig fields `cosim validate` takes as options (--wall-model for wall_model, ...), each parsed, checked
# and described from its declaration; not given, the default scene's value (`cosim scene --dump`)
NUMERICS_OPTIONS = ("free_liquid", "density_iteration", "density_tolerance", "divergence_constraint", "wall_model", "wall_pressure", "initial_state", "surface_density", "free_liquid_rule",
                    "free_surface_threshold", "artificial_viscosity", "artificial_viscosity_scale", "free_artificial_viscosity",
                    "artificial_viscosity_beta", "max_tension", "tension_treatment", "density_diffusion_term", "particle_shifting", "shifting_coefficient", "viscous_time_step")


def register(subparsers, summary: str) -> None:
    p = subparsers.add_parser("validate", help=summary, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("cases", nargs="*", metavar="CASE",
                   help="; ".join(f"{k}: {c.summary}" for k, c in CASES.items()) + f" (default: {' '.join(DEFAULT_CASES)})")
    p.add_argument("--json", action="store_true", help="print machine-readable results (with raw series) on stdout")
    p.add_argument("--width", type=float, help="tank width B (hydrostatic, slosh, slosh-plant; slosh-plant's cylinder: inner "
                   "diameter) or column width a (dam-break), m")
    p.add_argument("--fill", type=float, help="fill depth A (hydrostatic, slosh, slosh-plant) or column height (dam-break), m; "
                   "slosh without --fill runs the fills 0.054, 0.108, 0.162 m of Camporredondo et al. (2019)")
    p.add_argument("--gate-speed", type=float, metavar="M/S",
                   help="dam-break: release the column by a gate lifted at this speed, m/s (default: released instantaneously; "
                   "0.53 m/s lifts it off Martin & Moyce's column in Lauber & Hager's time sqrt(2 a / g), the JSON's lauber_hager_speed)")
    p.add_argument("--shape", choices=("box", "cylinder"), help="slosh-plant's vessel: box or cylinder (3-D only) (default box)")
    p.add_argument("--scene", help="a scene file whose pourer (a box, cylinder or mesh) is the vessel (hydrostatic, tilt, shake)")
    p.add_argument("--spacing", type=float, help="particle spacing dx, m (default: each case's resolution)")
    p.add_argument("--dim", type=int, default=FluidConfig.dim, help=f"2: 2-D (pour plane), 3: 3-D (default {FluidConfig.dim})")
    p.add_argument("--device", default="cpu", help="cpu or cuda[:N] (default cpu)")
    p.add_argument("--solver", choices=[s.value for s in PressureSolver],
                   help="pressure solver: wcsph (weakly compressible) or dfsph (divergence-free) (default: the default scene's "
                   "fluid.pressure_solver, as `cosim scene --dump` prints it)")
    _add_numerics_options(p)
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"folder for the PNG plots (default {DEFAULT_OUT})")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plots")
    p.add_argument("--strict", action="store_true", help="exit with status 1 if any validation fails")
    p.set_defaults(func=run)


def _case_params(name: str, args) -> list:
    from cosim.pour_scene import FluidSettings
    from cosim.validation import slosh, weir

    solver = args.solver or FluidSettings().pressure_solver.value
    numerics = _numerics(args, FluidSettings())
    common = {"dim": declared(FluidConfig, "dim").check("--dim", args.dim), "device": args.device, "spacing": args.spacing, "solver": solver, "numerics": numerics}
    geometry = {k: v for k, v in (("width", args.width), ("fill", args.fill)) if v is not None}
    params = CASES[name].params
    if name in ("tilt", "shake", "free-fall", "coupling-static"):
        geometry.pop("width", None)  # the scene's pouring vessel
    if name == "outflow":
        return [params(**common, head=head) for head in weir.HEADS]  # the weir's own channel, at two heads
    if name == "dam-break" and args.gate_speed is not None:
        geometry["gate_speed"] = args.gate_speed
    if name == "slosh-plant" and args.shape is not None:
        geometry["shape"] = args.shape
    if args.scene is not None and name in ("hydrostatic", "tilt", "shake"):
        geometry["scene"] = args.scene
        geometry.pop("width", None)
    if name == "slosh" and args.fill is None:
        return [params(**common, **geometry, fill=fill) for fill in slosh.SEED_FILLS]
    return [params(**common, **geometry)]


def _option(name: str) -> str:
    """The command-line flag of FluidConfig field ``name``: --wall-model for wall_model."""
    return "--" + name.replace("_", "-")


def _add_numerics_options(p: argparse.ArgumentParser) -> None:
    """One option per :data:`NUMERICS_OPTIONS` field, its allowed values from the field's declaration."""
    for name in NUMERICS_OPTIONS:
        spec = declared(FluidConfig, name)
        unset = "; 'none' leaves it unset" if spec.optional else ""
        p.add_argument(_option(name), dest=name, metavar=name.upper(),
                       help=f"fluid.{name}: {spec.allowed()}{unset} (default: the default scene's)")


def _numerics(args: argparse.Namespace, scene) -> tuple[tuple[str, object], ...]:
    """The (field, value) overrides every case runs with: each :data:`NUMERICS_OPTIONS` field as given on the command
    line (checked against its declaration; 'none' unsets an optional one) or else as in the default ``scene``."""
    pairs = []
    for name in NUMERICS_OPTIONS:
        text = getattr(args, name)
        value = getattr(scene, name) if text is None else _parse_setting(name, text)
        pairs.append((name, value.value if isinstance(value, Enum) else value))
    return tuple(pairs)


def _parse_setting(name: str, text: str):
    """FluidConfig field ``name``'s value from the command line's ``text``; one :class:`InputError` line naming the
    option and its allowed values where it is not one of them."""
    spec = declared(FluidConfig, name)
    if spec.optional and text.strip().lower() == "none":
        return None
    if spec.kind == "choice":
        return spec.check(_option(name), text)
    if spec.kind == "bool":
        words = {"true": True, "false": False}
        return spec.check(_option(name), words.get(text.strip().lower(), text))
    try:
        number = int(text) if spec.kind == "int" else float(text)
    except ValueError:
        raise InputError(f"{_option(name)}: must be {spec.allowed()}, got {text!r}") from None
    return spec.check(_option(name), number)


def _json_value(value):
    """numpy scalars and arrays as plain JSON numbers and lists."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def _table(results: list[CaseResult]) -> str:
    header = f"{'case':<12} {'quantity':<28} {'measured':>12} {'reference':>12} {'error':>9} {'tol':>7} {'pass':>5} {'wall s':>7}"
    lines = [header, "-" * len(header)]
    for r in results:
        label = r.case
        if r.case == "slosh":
            label = f"slosh A={r.parameters['fill']:.3f}"
        elif r.case == "outflow":
            label = f"outflow H0={r.parameters['head']:.3f}"
        for k, m in enumerate(r.metrics):
            err = f"{m.error:+.4f}" if m.absolute else f"{100 * m.error:+.2f}%"
            tol = ("-" if m.tolerance == float("inf") else (f"{m.tolerance:g}" if m.absolute else f"{100 * m.tolerance:g}%"))
            status = "ok" if m.passed else "FAIL"
            wall = f"{r.wall_time:7.1f}" if k == 0 else ""
            lines.append(f"{label if k == 0 else '':<12} {m.name:<28} {m.measured:>12.5g} {m.reference:>12.5g} {err:>9} {tol:>7} {status:>5} {wall:>7}")
    return "\n".join(lines)


def run(args) -> int:
    names = args.cases or list(DEFAULT_CASES)
    unknown = [n for n in names if n not in CASES]
    if unknown:
        raise InputError(f"case {unknown[0]!r}: unknown; choose from {', '.join(CASES)}")
    jobs = [(name, params) for name in names for params in _case_params(name, args)]  # validates every input first
    if not args.no_plot:
        check_output_folder(args.out, "--out")
    if args.device != "cpu":  # an absent device refused before any case runs (warp imported only for this)
        from cosim.fluid.runtime import resolve_device

        resolve_device(args.device)
    results = []
    for name, params in jobs:
        print(f"running {name} ({', '.join(f'{k}={v}' for k, v in vars(params).items() if v is not None)}) ...", file=sys.stderr)
        result = CASES[name].run(params)
        results.append(result)
        for extent in ("width", "depth") if not getattr(params, "scene", "") else ():  # tanks of whole spacings
            asked, built = getattr(params, extent, None), result.parameters.get(extent)
            if asked is not None and built is not None and built != asked:
                print(f"  {extent} {built:.4g} m: {asked:g} m rounded to whole particle spacings", file=sys.stderr)
        if not args.no_plot:
            suffix = f"-A{result.parameters['fill']:.3f}" if name in ("slosh", "slosh-plant") else ""
            suffix = f"-H{result.parameters['head']:.3f}" if name == "outflow" else suffix
            path = args.out / f"{name}{suffix}-{result.parameters['dim']}d.png"
            with atomic_path(path) as tmp:
                CASES[name].plot(result, tmp)
            print(f"  plot: {path}", file=sys.stderr)
    passed = all(r.passed for r in results)
    if args.json:
        print(json.dumps({"passed": passed, "cases": [r.to_json() for r in results]}, default=_json_value))
    else:
        print(_table(results))
        print(f"\n{'all validations passed' if passed else 'SOME VALIDATIONS FAILED (see FAIL rows)'}")
    return 1 if (args.strict and not passed) else 0
