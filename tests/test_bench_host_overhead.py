"""The host-cost benchmark (cosim.bench.host_overhead): its split of a pour's wall time and its input checks."""

from cosim.bench import host_overhead
from cosim.fluid.config import PressureSolver
from cosim.pour_scene import PourScene


def test_the_split_partitions_the_steps_wall_time():
    scene = host_overhead.scene_variant(PourScene(), PressureSolver.DFSPH, 12, "cpu")
    assert scene.fluid.particles_across == 12 and scene.fluid.pressure_solver is PressureSolver.DFSPH
    assert not scene.logging.enabled
    split = host_overhead.time_pour(scene, 0.02)
    assert split.steps == 10 and split.step_s == 0.002  # 20 ms of 2 ms MuJoCo steps
    assert split.particles > 0
    # the substeps run inside the timed steps: both parts are positive and sum to the steps' wall time
    assert 0.0 < split.substep_s < split.wall_s
    assert abs(split.host_ms_per_step + split.substep_ms_per_step - 1e3 * split.wall_s / split.steps) < 1e-9


def test_bad_input_is_one_line_and_exit_status_2(capsys):
    assert host_overhead.main(["--duration", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "error: --duration: must be in (0, 60] s, got 0" and "\n" not in err
    assert host_overhead.main(["--repeats", "0"]) == 2
