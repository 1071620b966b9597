"""The checks that need a CUDA device, as one short prepared run on a machine that has one.

    python -m cosim.bench.device_check [--device cuda] [--out DIR] [--quick]

Each check runs in its own process under its own time limit (a crash or a hang costs that check only), and the
report, DIR/device_check.md, is printed at the end:

1. agreement: the same short runs on the CPU and on the device: a tank tilted and shaken for 40 ms
   (:data:`AGREEMENT_INTERVALS` intervals of 4 ms), WCSPH and DFSPH, 2-D and 3-D; the largest particle position
   difference in particle spacings and the largest wrench difference over the liquid's weight, beside the same
   differences between two CPU runs whose initial positions differ by one float32 ulp (what rounding alone grows
   to in this flow: the yardstick for the device's difference); the device run
   with its substeps replayed as captured graphs against launched one by one (and why capture failed, if it did).
2. validation: the hydrostatic tank (0.5 s) and the slosh case (:data:`SLOSH_PERIODS` periods) on both: every metric side by side.
3. throughput: ``cosim.bench.fluid_throughput`` on the device (the speed targets' sizes: 2-D 10k, 3-D 100k and 1M
   particles, both solvers, warp's ``example_sph`` beside the 3-D rows; DFSPH again with the Jacobi density iteration), and
   the 2-D rows again without graph replay.
4. pour: the coupled pour (robots, controllers, trajectory generation, no recording) on the device: the default
   2-D scene (its own solver, DFSPH with Gauss-Seidel density sweeps), and the 3-D one at 64 across (~112k
   particles) under WCSPH and DFSPH with the Jacobi density solve (the GPU's choice for large scenes: a Gauss-Seidel
   colour runs a 27th of the occupied cells at once), :data:`POUR_SECONDS` simulated
   after a warm-up that compiles the kernels and captures the graphs; real-time factor, the wall time per 2 ms
   MuJoCo step split into the substeps and the rest (``cosim.bench.host_overhead``: the rest bounds the real-time
   factor), and the particle-substeps per second real time would take (particles x substeps per simulated
   second: what the device must sustain, besides the host's share); and where the 2-D pour's host time goes
   (cProfile, OUT/pour_host_profile.txt).
5. profile: ``cosim.bench.kernel_profile``, each kernel's device time in a substep of the benchmark's block (its
   default cases: 3-D at 1M and 2-D at 10k particles, WCSPH and DFSPH with either density iteration).

Sized to finish within 600 s (:data:`TIME_LIMITS`, one per check); docs/performance.md has the timings measured.

``--quick`` runs every check at small sizes (on the CPU too): a dry run of the machinery, numbers meaningless.
Needs warp, mujoco, ruckig and control; not rerun-sdk or tqdm.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from cosim.atomic_files import write_text_atomic

AGREEMENT_INTERVALS = 10  # of 4 ms: long enough for the graph replay (from the second interval on) to matter
AGREEMENT_INTERVAL = 0.004  # s
# s simulated and timed per pour, by dimension (after the warm-up): the 3-D pour at 112k particles plans 30,000
# WCSPH substeps per simulated second (3,000 DFSPH), so 0.5 s is 15,000 substeps (their cost: docs/performance.md)
POUR_SECONDS = {2: 2.0, 3: 0.5}
# slosh periods run (the frequency is measured from a quarter period after the pulse: 2 periods leave the window
# too few zero crossings to give one)
SLOSH_PERIODS = 3.0
HOST_PROFILE_SECONDS = 0.5  # s of the 2-D pour simulated under cProfile (its host side: pour_host_profile.txt)
HOST_PROFILE_LINES = 30  # functions listed
POUR_3D_ACROSS = 64  # particles across the pourer of the 3-D pour: 111,936 particles
# seconds each check may take: together within 600 s, so that all of them fit one time-limited run on a GPU machine
TIME_LIMITS = {"agreement": 90, "validation": 90, "throughput": 120, "pour": 180, "profile": 90}
CHECKS = tuple(TIME_LIMITS)


# ---- agreement --------------------------------------------------------------------------------------------
def _tank_run(device: str, solver: str, dim: int, across: int, graphs: bool, nudge: bool = False) -> dict:
    """A tank of liquid tilted and shaken for AGREEMENT_INTERVALS intervals: positions, wrenches, substeps.
    ``nudge``: every initial coordinate moved one float32 ulp up (the run's sensitivity to its last bit)."""
    from cosim.bench.host_overhead import capture_status
    from cosim.fluid.config import FluidConfig
    from cosim.fluid.seeding import fill_vessel
    from cosim.fluid.solver import FluidSolver
    from cosim.frames import Pose, rotation_y
    from cosim.vessel import VesselSpec

    width, fill = 0.1, 0.06
    tank = VesselSpec(name="tank", inner_width=width, inner_depth=width, inner_height=0.15)
    cfg = FluidConfig(
        dim=dim, spacing=width / across, pressure_solver=solver, max_expected_speed=2 * math.sqrt(9.81 * fill),
        domain_min=(-0.15, -0.15, -0.05), domain_max=(0.15, 0.15, 0.25),
    )
    liquid = fill_vessel(tank, fill, cfg)
    if nudge:
        liquid.positions[:] = np.nextafter(liquid.positions.astype(np.float32), np.float32(np.inf))
    fluid = FluidSolver(cfg, [tank], [Pose()], liquid, device=device, graphs=graphs)
    for k in range(1, AGREEMENT_INTERVALS + 1):
        phase = k / AGREEMENT_INTERVALS
        fluid.set_vessel_poses([Pose((0.005 * math.sin(2 * math.pi * phase), 0.0, 0.0), rotation_y(0.1 * phase))])
        fluid.advance(AGREEMENT_INTERVAL)
    weight = fluid.n_particles * cfg.particle_mass * cfg.out_of_plane_scale * 9.81
    return {
        "x": fluid.positions(), "wrench": fluid.vessel_wrenches(), "steps": fluid.step_count, "spacing": cfg.spacing,
        "weight": weight, "particles": fluid.n_particles, "graphs": capture_status(fluid),
    }


def _difference(a: dict, b: dict) -> dict:
    return {
        "max_dx_over_spacing": float(np.abs(a["x"] - b["x"]).max() / a["spacing"]),
        "max_wrench_over_weight": float(np.abs(a["wrench"] - b["wrench"]).max() / a["weight"]),
        "substeps": f"{a['steps']} / {b['steps']}",
    }


def check_agreement(device: str, quick: bool) -> list[dict]:
    rows = []
    for dim, across in ((2, 12 if quick else 24), (3, 6 if quick else 12)):
        for solver in ("wcsph", "dfsph"):
            cpu = _tank_run("cpu", solver, dim, across, False)
            nudged = _tank_run("cpu", solver, dim, across, False, nudge=True)
            graphs = _tank_run(device, solver, dim, across, True)
            launches = _tank_run(device, solver, dim, across, False)
            rows.append({
                "dim": dim, "solver": solver, "particles": cpu["particles"],
                "cpu_vs_device": _difference(cpu, graphs), "graphs_vs_launches": _difference(graphs, launches),
                "one_ulp": _difference(cpu, nudged), "graphs": graphs["graphs"],
            })
    return rows


def _agreement_table(rows: list[dict]) -> list[str]:
    out = [
        "| case | particles | CPU vs device: max dx / spacing | max wrench / weight | substeps | "
        "CPU vs CPU nudged 1 ulp: max dx / spacing | max wrench / weight | graphs vs launches: max dx / spacing | graph capture |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        c, u, g = r["cpu_vs_device"], r["one_ulp"], r["graphs_vs_launches"]
        out.append(f"| {r['dim']}-D {r['solver']} | {r['particles']} | {c['max_dx_over_spacing']:.2e} | {c['max_wrench_over_weight']:.2e} | "
                   f"{c['substeps']} | {u['max_dx_over_spacing']:.2e} | {u['max_wrench_over_weight']:.2e} | {g['max_dx_over_spacing']:.2e} | {r['graphs']} |")
    out += ["", "The 1-ulp columns are the CPU run's own sensitivity: a device difference of that size is rounding grown by the flow."]
    return out


# ---- validation -------------------------------------------------------------------------------------------
def check_validation(device: str, quick: bool) -> list[dict]:
    from cosim.validation import hydrostatic, slosh

    runs = (
        ("hydrostatic", hydrostatic.run, lambda d: hydrostatic.Params(device=d, solver="wcsph", duration=0.05 if quick else 0.5, spacing=0.191 / 16 if quick else None)),
        ("slosh", slosh.run, lambda d: slosh.Params(device=d, solver="wcsph", periods=0.5 if quick else SLOSH_PERIODS, spacing=0.191 / 16 if quick else None)),
    )
    rows = []
    for name, run, params in runs:
        cpu, dev = run(params("cpu")), run(params(device))
        for a, b in zip(cpu.metrics, dev.metrics):
            rows.append({"case": name, "metric": a.name, "unit": a.unit, "cpu": a.measured, "device": b.measured,
                         "cpu_wall_s": cpu.wall_time, "device_wall_s": dev.wall_time})
    return rows


def _validation_table(rows: list[dict]) -> list[str]:
    out = ["| case | metric | CPU | device | difference |", "|---|---|---|---|---|"]
    for r in rows:
        diff = r["device"] - r["cpu"]
        out.append(f"| {r['case']} | {r['metric']} ({r['unit'] or '-'}) | {r['cpu']:.6g} | {r['device']:.6g} | {diff:+.3g} |")
    walls = {r["case"]: (r["cpu_wall_s"], r["device_wall_s"]) for r in rows}
    out.append("")
    out += [f"{case}: wall time {c:.1f} s on the CPU, {d:.1f} s on the device." for case, (c, d) in walls.items()]
    return out


# ---- throughput -------------------------------------------------------------------------------------------
def check_throughput(device: str, quick: bool, out: Path) -> list[dict]:
    from cosim.bench import fluid_throughput

    counts2d, counts3d = (["500"], ["2000"]) if quick else (["10000"], ["100000", "1000000"])
    table = out / "throughput.md"
    table.unlink(missing_ok=True)  # the benchmark appends: start this run's table afresh
    where = ["--device", device, "--out", str(table)]
    both = ["--solvers", "wcsph", "dfsph"]
    fluid_throughput.main(["--counts2d", *counts2d, "--counts3d", *counts3d, *both, *where])
    fluid_throughput.main(["--counts2d", *counts2d, "--counts3d", *counts3d, "--solvers", "dfsph", "--density-iteration", "jacobi", *where])
    fluid_throughput.main(["--counts2d", *counts2d, "--counts3d", "--no-graphs", *both, *where])
    return [{"table": table.read_text()}]


# ---- pour -------------------------------------------------------------------------------------------------
def profile_host(device: str, seconds: float, out: Path) -> None:
    """Where the default 2-D pour's host time goes on ``device``: ``seconds`` simulated under cProfile after the
    warm-up, the functions by their own time, written to OUT/pour_host_profile.txt (the profiler slows the Python
    side, so the shares, not the times, are the result)."""
    import cProfile
    import io
    import pstats

    from cosim.bench.host_overhead import time_steps, warm_pour
    from cosim.pour_scene import FluidSettings

    pour = warm_pour(device, 2, FluidSettings().particles_across, seconds, FluidSettings().pressure_solver.value, FluidSettings().density_iteration.value)
    profiler = cProfile.Profile()
    profiler.runcall(time_steps, pour, seconds)
    text = io.StringIO()
    pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(HOST_PROFILE_LINES)
    write_text_atomic(out / "pour_host_profile.txt", text.getvalue())


def check_pour(device: str, quick: bool, out: Path) -> list[dict]:
    from cosim.bench.host_overhead import pour_rate

    if quick:
        rows = [pour_rate(device, 2, 32, 0.05), pour_rate(device, 3, 12, 0.05, "wcsph"), pour_rate(device, 3, 12, 0.05, "dfsph", "jacobi")]
    else:
        rows = [
            pour_rate(device, 2, 32, POUR_SECONDS[2]),
            pour_rate(device, 3, POUR_3D_ACROSS, POUR_SECONDS[3], "wcsph"),
            pour_rate(device, 3, POUR_3D_ACROSS, POUR_SECONDS[3], "dfsph", "jacobi"),
        ]
    profile_host(device, 0.05 if quick else HOST_PROFILE_SECONDS, out)
    return rows


def _pour_table(rows: list[dict]) -> list[str]:
    out = [
        "| pour | particles | simulated s | wall s | real-time factor | SPH substeps | real time needs (G particle-substeps/s) | "
        "substeps ms per MuJoCo step | the rest (host) ms per step | graph capture |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        needed = r["particles"] * r["sph_substeps"] / r["simulated_s"] / 1e9
        out.append(f"| {r['dim']}-D, {r['across']} across, {r['solver']} | {r['particles']} | {r['simulated_s']:g} | {r['wall_s']:.1f} | "
                   f"{r['real_time_factor']:.3f} | {r['sph_substeps']} | {needed:.3f} | {r['substeps_ms_per_step']:.3f} | "
                   f"{r['host_ms_per_step']:.3f} | {r['graphs']} |")
    return out


# ---- profile ----------------------------------------------------------------------------------------------
def check_profile(device: str, quick: bool, out: Path) -> list[dict]:
    from cosim.bench import kernel_profile

    cases = ["3:2000:wcsph", "2:500:dfsph:jacobi"] if quick else []
    kernel_profile.main(["--device", device, "--out", str(out), *(["--cases", *cases] if cases else [])])
    body = (out / "kernel_profile.md").read_text().split("\n", 1)[1]  # without its title: the report has one
    return [{"table": body.replace("\n## ", "\n### ")}]


# ---- driver -----------------------------------------------------------------------------------------------
def _text(output: bytes | str | None) -> str:
    """A timed-out child's captured output as text (``subprocess`` hands it back as bytes, or None)."""
    if isinstance(output, bytes):
        return output.decode(errors="replace")
    return output or ""


def _run_one(check: str, device: str, quick: bool, out: Path) -> list[dict]:
    if check == "agreement":
        return check_agreement(device, quick)
    if check == "validation":
        return check_validation(device, quick)
    if check == "throughput":
        return check_throughput(device, quick, out)
    if check == "profile":
        return check_profile(device, quick, out)
    return check_pour(device, quick, out)


def _report(results: dict[str, dict], device: str, quick: bool) -> str:
    tables = {"agreement": _agreement_table, "validation": _validation_table, "pour": _pour_table}
    lines = [f"# Device check ({device}{', quick: numbers meaningless' if quick else ''})", ""]
    for check in CHECKS:
        r = results.get(check)
        lines.append(f"## {check}")
        lines.append("")
        if r is None:
            lines.append("not run")
        elif r["status"] != "ok":
            lines.append(f"{r['status']} after {r['wall_s']:.0f} s: {r.get('error', '')}")
        elif check in ("throughput", "profile"):
            lines.append(r["rows"][0]["table"].strip())
        else:
            lines += tables[check](r["rows"])
        if r is not None:
            lines += ["", f"({r['wall_s']:.0f} s)"]
        lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--device", default="cuda", help="the device to check against the CPU (default cuda)")
    p.add_argument("--out", type=Path, default=Path("recordings") / "device_check", help="folder for the report and raw results")
    p.add_argument("--quick", action="store_true", help="small sizes: a dry run of the machinery (numbers meaningless)")
    p.add_argument("--only", choices=CHECKS, nargs="*", default=list(CHECKS), help="run these checks only")
    p.add_argument("--child", choices=CHECKS, help=argparse.SUPPRESS)  # one check, in the process the driver started
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.child:
        rows = _run_one(args.child, args.device, args.quick, args.out)
        write_text_atomic(args.out / f"{args.child}.json", json.dumps(rows, indent=1))
        return 0
    results = {}
    for check in args.only:
        cmd = [sys.executable, "-m", "cosim.bench.device_check", "--child", check, "--device", args.device, "--out", str(args.out)]
        cmd += ["--quick"] if args.quick else []
        start = time.perf_counter()
        print(f"device check: {check} ...", flush=True)
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=TIME_LIMITS[check])
            status = "ok" if done.returncode == 0 else f"failed (exit {done.returncode})"
            error = done.stderr.strip().splitlines()[-1] if done.returncode and done.stderr.strip() else ""
            write_text_atomic(args.out / f"{check}.log", done.stdout + done.stderr)
        except subprocess.TimeoutExpired as timed_out:  # keep what the check printed before its limit
            status, error = "timed out", f"the {TIME_LIMITS[check]} s limit"
            write_text_atomic(args.out / f"{check}.log", _text(timed_out.stdout) + _text(timed_out.stderr))
        result = {"status": status, "wall_s": time.perf_counter() - start, "error": error}
        if status == "ok":
            result["rows"] = json.loads((args.out / f"{check}.json").read_text())
        results[check] = result
    report = _report(results, args.device, args.quick)
    write_text_atomic(args.out / "device_check.md", report + "\n")
    print(report)
    return 0 if all(r["status"] == "ok" for r in results.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
