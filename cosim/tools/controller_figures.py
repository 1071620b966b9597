"""Model versions of the controller figures of Camporredondo et al. (2019) (the SPH versions come from the coupled
simulation).

    python -m cosim.tools.controller_figures --out DIR [--plant potential-flow|printed-paper]

writes, for the paper's vessel (B = L = 0.191 m, A = 0.1591 m) and the default configuration, on the physical
slosh model (potential flow, the default) or, to reproduce the paper's own figures, on its Eqs. 10-11 as printed
(:func:`controllers.slosh.printed_paper_model`):
  fig13_theta1_ratio.png    theta1/theta against the excitation frequency, fills A = 54..162 mm (Eq. 13; Fig. 13)
  fig14_root_locus.png      root loci of Gp and of C Gp with the design's closed-loop poles (Fig. 14)
  fig15_step_response.png   step responses of Gp and C Gp in unity feedback (Fig. 15)
  fig16_sim_timeline.png    the SIM timeline theta, theta1 and the slosh angle on the model plant (Fig. 16)
and prints the design's numbers. Figures are drawn off-screen (matplotlib's Agg backend, chosen by :func:`main`).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import control as ct
import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from controllers.config import CatcherConfig, PourConfig
from controllers.measurement import Phase
from controllers.model_plant import ModelPlant, ModelPlantConfig, Trace, run_closed_loop
from controllers.pid import PidDesign, PidDesignSpec, actuator, delayed_loop, design_filtered_pid
from controllers.pour import PourController
from controllers.slosh import potential_flow_model, printed_paper_model

PAPER_FILLS_MM = (54, 81, 108, 135, 162)  # the paper's Sec. 4 tests fills from 54 to 162 mm
PLANTS = {"potential-flow": potential_flow_model, "printed-paper": printed_paper_model}
SIM_PLOT_SECONDS = 4.0  # s of the SIM timeline plotted: excitation, hold, damping and the start of CFS
PHASE_COLOURS = {
    Phase.SIM_EXCITE: "#fde0c5",
    Phase.SIM_HOLD: "#fff3b0",
    Phase.SIM_DAMP: "#d4edda",
    Phase.CFS: "#d6e4f0",
    Phase.CFS_FINAL: "#c3d5ea",
}


def paper_config(plant: str = "potential-flow") -> PourConfig:
    """The default pour of the paper's vessel and fill on the slosh model ``plant`` (a key of :data:`PLANTS`);
    vessel B's home is arbitrary for these figures."""
    config = PourConfig(catcher=CatcherConfig(home_x=0.25))
    model = PLANTS[plant](config.vessel.inner_width, config.fill_depth, config.gravity)
    return PourConfig(catcher=config.catcher, slosh=model)


def figure_ratio(path: Path, config: PourConfig, plant: str) -> None:
    width = config.vessel.inner_width
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for fill_mm in PAPER_FILLS_MM:
        model = PLANTS[plant](width, fill_mm / 1000.0, config.gravity)
        alpha = np.linspace(0.0, 0.97 * model.omega1, 400)
        ax.plot(alpha, np.abs(model.forced_ratio(alpha)), label=f"A = {fill_mm} mm (omega1 = {model.omega1:.1f} rad/s)")
    own = config.slosh_model()
    ax.axvline(config.sim.frequency_ratio * own.omega1, color="k", ls="--", lw=1, label="SIM alpha (A = 159 mm)")
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set(xlabel="excitation frequency alpha (rad/s)", ylabel="|theta1 / theta|", ylim=(0.0, 4.0),
           title=f"Forced slosh response, pendulum model (paper Eq. 13; {own.source})")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _locus(ax: plt.Axes, open_loop: ct.TransferFunction, marked: np.ndarray, title: str, max_gain: float) -> None:
    gains = np.concatenate([[0.0], np.logspace(-3, math.log10(max_gain), 1500)])
    loci = ct.root_locus_map(open_loop, gains=gains).loci
    ax.plot(loci.real, loci.imag, ".", ms=1.5, color="tab:blue")
    ax.plot(ct.poles(open_loop).real, ct.poles(open_loop).imag, "x", color="k", ms=8, label="open-loop poles")
    z = ct.zeros(open_loop)
    ax.plot(z.real, z.imag, "o", mfc="none", color="k", ms=8, label="zeros")
    ax.plot(marked.real, marked.imag, "s", color="tab:red", ms=6, label="closed loop, gain 1")
    ax.axvline(0.0, color="grey", lw=0.8)
    ax.set(xlabel="Re (rad/s)", ylabel="Im (rad/s)", title=title)
    ax.legend(fontsize=7, loc="lower left")


def figure_root_locus(path: Path, design: PidDesign) -> None:
    gp = design.model.plant()
    gpc = design.gains.transfer_function() * gp
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.6))
    _locus(a1, gp, ct.poles(ct.feedback(gp, 1)), "k Gp: poles stay on the imaginary axis", 1e3)
    a1.set(xlim=(-80, 80), ylim=(-60, 60))
    _locus(a2, gpc, design.closed_loop_poles, "k C Gp (filtered PID)", 1e2)
    a2.set(xlim=(-80, 80), ylim=(-40, 40))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def figure_step(path: Path, design: PidDesign, spec: PidDesignSpec) -> None:
    gp = design.model.plant()
    t = np.linspace(0.0, 3.0, 3001)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True)
    _, y = ct.step_response(ct.feedback(gp, 1), T=t)
    a1.plot(t, y)
    a1.axhline(0.5, color="grey", ls="--", lw=0.8)
    a1.set(ylabel="theta1 (rad per rad)", title="Gp in unity feedback: undamped, mean 1/2 (error 1/2)")
    measured = ct.tf(*design.measurement, design.dt)  # theta1 as the PID reads it, through its measurement filter
    sampled = ct.feedback(delayed_loop(design.gains, design.model, design.dt, actuator(spec, design.dt)), measured)
    ts, y = ct.step_response(sampled, T=np.arange(0.0, 3.0, design.dt))
    a2.step(ts, y, where="post")
    a2.axhline(1.0, color="grey", ls="--", lw=0.8)
    g = design.gains
    a2.set(xlabel="t (s)", ylabel="theta1 (rad per rad)",
           title=f"C Gp at {1 / design.dt:g} Hz, smoother, {1e3 * spec.actuation_delay:g} ms, theta1 filter: Kp={g.kp:.3f}, "
           f"Ki={g.ki:.3f}/s, Kd={g.kd:.4f} s, Tf={1e3 * g.tf:.1f} ms; decays at {design.decay_rate:.1f} /s")
    a2.title.set_fontsize(9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def sim_timeline(config: PourConfig) -> tuple[PourController, Trace]:
    """The controller's SIM timeline on the model plant (pendulum + box + weir), first SIM_PLOT_SECONDS."""
    controller = PourController(config)
    plant = ModelPlant(ModelPlantConfig(vessel=config.vessel, fill_depth=config.fill_depth, slosh=config.slosh), config.dt)
    return controller, run_closed_loop(controller, plant, SIM_PLOT_SECONDS)


def figure_sim_timeline(path: Path, config: PourConfig) -> PourController:
    """Draw Fig. 16 (model version); returns the controller that ran it (its transitions, SIM parameters)."""
    controller, trace = sim_timeline(config)
    t = trace.t
    theta = np.degrees([c.pourer.theta for c in trace.commands])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True)
    a1.plot(t, theta, label="theta (vessel tilt, command)")
    a1.plot(t, np.degrees(trace.series("theta1")), label="theta1 (free surface, vessel frame)")
    a1.plot(t, np.degrees(trace.series("theta1") - trace.series("tilt")), label="sigma = theta1 - theta (slosh)")
    a1.set(ylabel="angle (deg)", title="SIM timeline on the pendulum model (paper Figs. 7, 16)")
    a1.legend(fontsize=8)
    a2.plot(t, 1e3 * trace.series("h_q"), color="tab:purple", label="h_q")
    a2.axhline(1e3 * config.cfs.h_q_ref, color="grey", ls="--", lw=0.8, label="h_q reference")
    a2.set(xlabel="t (s)", ylabel="h_q (mm)", ylim=(-40, 15))
    a2.legend(fontsize=8)
    for phase, t0, t1 in controller.phase_intervals(float(t[-1])):
        colour = PHASE_COLOURS.get(Phase(phase))
        if colour:
            for ax in (a1, a2):
                ax.axvspan(t0, t1, color=colour, lw=0)
            a1.text(0.5 * (t0 + t1), a1.get_ylim()[1], phase, ha="center", va="top", fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return controller


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cosim.tools.controller_figures", description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="directory for the PNG files")
    parser.add_argument("--plant", choices=sorted(PLANTS), default="potential-flow",
                        help="slosh model: potential flow (physical, the default) or the paper's Eqs. 10-11 as printed")
    args = parser.parse_args(argv)
    matplotlib.use("Agg")
    args.out.mkdir(parents=True, exist_ok=True)
    config = paper_config(args.plant)
    model = config.slosh_model()
    design = design_filtered_pid(model, config.sim.pid, config.dt)
    figure_ratio(args.out / "fig13_theta1_ratio.png", config, args.plant)
    figure_root_locus(args.out / "fig14_root_locus.png", design)
    figure_step(args.out / "fig15_step_response.png", design, config.sim.pid)
    controller = figure_sim_timeline(args.out / "fig16_sim_timeline.png", config)
    for name in ("fig13_theta1_ratio.png", "fig14_root_locus.png", "fig15_step_response.png", "fig16_sim_timeline.png"):
        print(args.out / name)
    g = design.gains
    print(f"plant ({model.source}): l1 = {model.l1:.5f} m, hinge {model.hinge_height:.5f} m, b2 = {model.b2:.5f} m, "
          f"omega1 = {model.omega1:.3f} rad/s, RHP zero = {model.rhp_zero:.2f} rad/s")
    print(f"PID: Kp = {g.kp:.4f}, Ki = {g.ki:.4f} 1/s, Kd = {g.kd:.5f} s, Tf = {g.tf:.5f} s")
    print("closed-loop poles (rad/s): " + ", ".join(f"{p:.3f}" for p in design.closed_loop_poles))
    print(f"sampled at {config.control_rate:g} Hz through the smoother and {1e3 * config.sim.pid.actuation_delay:g} ms: "
          f"max |z| = {np.max(np.abs(design.discrete_poles)):.4f} (decay {design.decay_rate:.2f} /s), "
          f"gain margin {design.gain_margin:.1f} dB, phase margin {design.phase_margin:.1f} deg")
    print(f"SIM: phi = {math.degrees(controller.sim_amplitude):.2f} deg, alpha = {controller.sim_frequency:.3f} rad/s")
    for tr in controller.transitions:
        print(f"  t = {tr.t:5.2f} s  {tr.source.value} -> {tr.target.value}: {tr.reason}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
