"""Slosh induction method, SIM (Camporredondo et al. 2019, Sec. 3.1, Figs. 4 and 7): when to use it and its excitation.

Timeline (Fig. 7), run by :class:`controllers.pour.PourController` about the centre of the inner floor:
  t0  excitation theta = phi sin(alpha t) until theta = phi (a quarter period, pi / (2 alpha));
  t1  hold theta = phi until the slosh angle sigma = theta1 - theta crosses zero toward the lip (the induced wave
      runs toward the lip with its largest speed) with the vessel itself at phi: the paper's theta1 returns to zero
      "while theta remains at phi". The arm reaches phi after its command does (its task-space filter and servos
      lag it), and a crossing while it still tilts is the surface answering that motion: counted, it would end t1
      at once or a slosh period later depending on a few milliseconds of phase (docs/controller.md);
  t2  PID damping of theta1 (:mod:`controllers.pid`, through the smoother it is designed with) toward the tilt at
      which the resting liquid would stand sim.damp_head (below the crest) over the crest;
  t3  hand-over to the constant-flow stage once |sigma| has stayed within sim.settle_tolerance for
      sim.settle_dwell, or after a timeout. The paper hands over when "the slosh finds free exit to flow out of the
      vessel" (h_q > 0); from then the crest clamps the surface and theta1 no longer follows Gp, so the PID would
      not be damping the plant it was designed on. Here the slosh is damped below the crest first, and CFS starts
      the outflow from a calm liquid.

Fill condition. The paper runs SIM when "h_e <= h_q at theta = 20 deg". Read literally (h_q = 5 mm) it would
exclude the paper's own vessel. Implemented reading: SIM is needed when the liquid would reach
the lip before the vessel has tilted by the trigger angle (20 deg), i.e. for a box whose level surface rises
by (B/2) tan(theta) at the front wall, when h_e = L - A <= (B/2) tan(20 deg). The paper's vessel: h_e = 31.9 mm <=
34.8 mm, so SIM runs.
"""

from __future__ import annotations

import math


def sim_needed(width: float, height: float, fill_depth: float, trigger_angle: float) -> tuple[bool, str]:
    """(needed, reason) of the fill condition h_e = L - A <= (B/2) tan(trigger_angle); lengths in m, angle in rad."""
    empty = height - fill_depth
    reach = 0.5 * width * math.tan(trigger_angle)
    deg = math.degrees(trigger_angle)
    if empty <= reach:
        return True, f"h_e = {1e3 * empty:.1f} mm <= (B/2) tan({deg:g} deg) = {1e3 * reach:.1f} mm: slosh induction"
    return False, f"h_e = {1e3 * empty:.1f} mm > (B/2) tan({deg:g} deg) = {1e3 * reach:.1f} mm: no slosh induction"


def excitation_tilt(elapsed: float, amplitude: float, alpha: float) -> float:
    """t0 tilt (rad) after ``elapsed`` s: amplitude sin(alpha elapsed), held at ``amplitude`` after a quarter period."""
    return amplitude * math.sin(min(alpha * elapsed, 0.5 * math.pi))


def excitation_duration(alpha: float) -> float:
    """Length of t0 (s): a quarter period of the excitation, pi / (2 alpha)."""
    return 0.5 * math.pi / alpha
