"""Side-view pictures of a finished pour, from its run folder (a tool for docs and debugging; it only reads).

    python -m cosim.tools.snapshot RUN [--times 2.0 5.0 8.0] [--stream] [--out RUN/snapshot.png]

Each panel is the pour plane (world x-z): the liquid particles logged in ``pour.rrd`` at the nearest logged time,
and the vessels and arm links of the scene posed by forward kinematics of the joint trajectory in ``trajectory.csv``
at that time (:meth:`cosim.robots.scene.RobotScene.posed`; every box geom as its outline in the plane, capsules and
cylinders as their axis). Without ``--times``, four times spread over the controller's pouring phases are taken from
``summary.json``. ``--stream`` draws, where liquid flows over the lip, the free-fall parabola the catcher aims
with (:func:`controllers.catcher.jet_path`, Eqs. 6-7 of Camporredondo et al. (2019), "A Kinematic Controller for
Liquid Pouring between Vessels Modelled with SPH", launched with the measured v_q from where it is measured,
``series.csv``) over the SPH stream, as in the paper's Fig. 10, and the landing point predicted at the catcher's rim
height.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import mujoco
import numpy as np

from controllers.catcher import jet_path
from cosim.atomic_files import atomic_path
from cosim.io.pour_series import read_series_csv
from cosim.io.rerun_paths import LIQUID
from cosim.io.rerun_read import read_component
from cosim.robots.scene import RobotScene
from cosim.trajectory.csv_file import read_trajectory_csv

BOX_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]], dtype=float)


def _default_times(summary: dict) -> list[float]:
    pouring = [p for p in summary["phases"] if p["phase"] not in ("idle", "done")]
    start, end = (pouring[0]["start"], pouring[-1]["end"]) if pouring else (0.0, summary["sim_time"])
    return list(np.linspace(start, end, 6)[1:5])


def _draw_scene(ax, model: mujoco.MjModel, data: mujoco.MjData) -> None:
    for g in range(model.ngeom):
        if model.geom_group[g] > 2 or model.geom_rgba[g, 3] == 0.0 or model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            continue
        pos, rot, size = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3), model.geom_size[g]
        color = model.geom_rgba[g, :3]
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX and abs(rot[1, 1]) > 0.99:  # boxes seen edge-on in x-z
            local = np.stack([BOX_CORNERS[:, 0] * size[0], np.zeros(5), BOX_CORNERS[:, 1] * size[2]], axis=1)
            world = local @ rot.T + pos
            ax.fill(world[:, 0], world[:, 2], color=color, alpha=0.5, lw=0.5)
        elif model.geom_type[g] in (mujoco.mjtGeom.mjGEOM_CAPSULE, mujoco.mjtGeom.mjGEOM_CYLINDER):
            ends = pos + np.outer([-1.0, 1.0], rot[:, 2] * size[1])
            ax.plot(ends[:, 0], ends[:, 2], color=color, lw=max(1.0, 200 * size[0]), alpha=0.6, solid_capstyle="round")


def _draw_parabola(ax, series: dict[str, np.ndarray], t: float) -> None:
    """The jet parabola predicted at the control step nearest ``t`` (if liquid flowed then), down to the rim."""
    k = int(np.argmin(np.abs(series["t"] - t)))
    h_q, v_x, v_z = series["h_q"][k], series["v_q"][k], series["v_q_z"][k]
    if not (h_q > 0.0 and v_x > 0.0):
        return
    x0, z0 = series["lip_x"][k] + series["jet_dx"][k], series["lip_z"][k] + series["jet_dz"][k]
    rim = series["catcher_rim_z"][k]
    x, z = jet_path(x0, z0, v_x, v_z, z0 - rim)
    ax.plot(x, z, "r--", lw=1.2, zorder=4, label="Eqs. 6-7 parabola")
    ax.plot([series["landing_x"][k]], [rim], "rx", ms=8, zorder=5, label="predicted landing")
    ax.legend(loc="upper right", fontsize=7)


def render(run: Path, times: list[float] | None, out: Path, stream: bool = False) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    summary = json.loads((run / "summary.json").read_text())
    times = times or _default_times(summary)
    liquid = read_component(run / "pour.rrd", LIQUID, "Points3D:positions")
    traj = read_trajectory_csv(run / "trajectory.csv")
    scene = RobotScene.load(summary.get("scene", {}).get("robots", {}).get("scene") or None)
    series = {k: np.asarray(v) for k, v in read_series_csv(run / "series.csv").items()} if stream else None
    fig, axes = plt.subplots(1, len(times), figsize=(4.2 * len(times), 4.6), dpi=110, squeeze=False)
    for ax, t in zip(axes[0], times):
        k = int(np.argmin(np.abs(traj.time - t)))
        data = scene.posed({role: traj.positions[k, traj.columns(arm.joints)] for role, arm in scene.arms.items()})
        _draw_scene(ax, scene.model, data)
        i = int(np.argmin(np.abs(liquid.sim_time - t)))
        points = liquid.values[i]
        ax.scatter(points[:, 0], points[:, 2], s=4, c="tab:blue", zorder=3)
        if series is not None:
            _draw_parabola(ax, series, liquid.sim_time[i])
        ax.set_title(f"t = {liquid.sim_time[i]:.2f} s")
        ax.set_aspect("equal")
        ax.set_xlim(-0.45, 0.75)
        ax.set_ylim(0.7, 1.6)
        ax.set_xlabel("world x (m)")
    axes[0][0].set_ylabel("world z (m)")
    fig.suptitle(f"{summary['scene_name']}: {summary['dim']}-D liquid, {summary['particles']} particles")
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp)
    plt.close(fig)
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", type=Path)
    p.add_argument("--times", type=float, nargs="*")
    p.add_argument("--stream", action="store_true", help="draw the predicted jet parabola where liquid flows")
    p.add_argument("--out", type=Path)
    args = p.parse_args(argv)
    print(render(args.run, args.times, args.out or args.run / "snapshot.png", args.stream))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
