"""The command-line options several benchmarks take, each declared once (:func:`declared_settings.setting.argument`)
and checked by its declaration under the option's name, e.g. ``DURATION.check("--duration", args.duration)``."""

from declared_settings.setting import argument

BENCH = "benchmark"
DURATION = argument(BENCH, "Simulated time of the pour that each run times.", "s", 0.0, 60.0, lo_open=True)
REPEATS = argument(BENCH, "Runs of each row (or command), of which the median is printed.", "", 1, 50, kind="int")
