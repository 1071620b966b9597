"""The default blueprint stored in the recording: the 3-D view of world framed by the camera given, the window's full
height beside the plots, the controller's log and the colour scale, one plot per signal titled with its unit in a tab
per group, legends only where a plot has several series, and the sim_time timeline."""

from __future__ import annotations

import uuid

import mujoco
import numpy as np
import pytest
import rerun.blueprint as rrb
from rerun.chunk import RrdReader

from cosim.io.recording import PourRecorder, RecordingConfig
from cosim.io.rerun_blueprint import Camera, colour_scale_text, panel_title, split_unit
from cosim.io.rerun_read import blueprint_camera, read_component

SIGNALS = {
    "pour/tilt_deg": {"commanded": 1.0, "measured": 2.0},
    "pour/volume_mL": {"in pourer": 1.0, "in catcher": 0.0, "outside": 0.0},
    "pour/head_over_crest_mm": 3.0,
    "pourer/liquid_force_N": {"x": 0.0, "y": 0.0, "z": -9.8},
    "pourer/liquid_torque_N_m": {"x": 0.0, "y": 0.1, "z": 0.0},
    "pour_arm/joint_speed_deg_s": {"shoulder_pan": 0.0, "elbow": 1.0},
}
# panel title -> (tab, legend shown)
PANELS = {
    "pour tilt (deg)": ("pour", True),
    "pour volume (mL)": ("pour", True),
    "pour head over crest (mm)": ("pour", False),
    "pourer liquid force (N)": ("pourer", True),
    "pourer liquid torque (N m)": ("pourer", True),
    "pour_arm joint speed (deg/s)": ("pour_arm", True),
}
SINGLE_BODY = "<mujoco><worldbody><body name='cup'><joint type='hinge'/><geom type='box' size='.1 .1 .1'/></body></worldbody></mujoco>"
CAMERA = Camera(eye=(0.1, 1.2, 1.5), target=(0.1, 0.0, 1.1))


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    model = mujoco.MjModel.from_xml_string(SINGLE_BODY)
    path = tmp_path_factory.mktemp("blueprint") / "pour.rrd"
    with PourRecorder(path, model, RecordingConfig(speed_color_max=1.5), camera=CAMERA, liquid_note="A 2-D slice.") as rec:
        for k in range(3):
            rec.log_scalars(0.01 * k, k, SIGNALS)
        rec.log_phase(0.0, 0, "SIM", "start")
    return path


def _blueprint(path) -> tuple[dict[str, dict], dict[str, dict]]:
    """Views and containers (id -> components of the item and its properties, the last row of each) and the other
    blueprint entities of the file."""
    reader = RrdReader(path)
    (entry,) = reader.blueprints()
    items: dict[str, dict] = {}
    other: dict[str, dict] = {}
    for chunk in reader.store(store=entry).stream():
        batch = chunk.to_record_batch()
        columns = {n: batch.column(n).to_pylist()[-1] for n in batch.schema.names if ":" in n}
        parts = chunk.entity_path.strip("/").split("/")
        if parts[0] in ("view", "container"):
            items.setdefault(parts[1], {}).update(columns)
        else:
            other[chunk.entity_path] = columns
    return items, other


def test_units_are_read_from_the_name():
    assert split_unit("pour_arm/joint_speed_deg_s") == ("joint_speed", "deg/s")
    assert split_unit("pourer/liquid_torque_N_m") == ("liquid_torque", "N m")
    assert split_unit("pour/volume_mL") == ("volume", "mL")
    assert split_unit("pour/theta1") == ("theta1", "")
    assert panel_title("catch_arm/joint_angle_deg") == "catch_arm joint angle (deg)"


def test_views_of_the_default_blueprint(recording):
    items, other = _blueprint(recording)
    views = [v for v in items.values() if "ViewBlueprint:class_identifier" in v]
    by_class: dict[str, list[dict]] = {}
    for view in views:
        by_class.setdefault(view["ViewBlueprint:class_identifier"][0], []).append(view)
    (space,) = by_class["3D"]
    assert space["ViewBlueprint:space_origin"] == ["world"]
    assert [v["ViewBlueprint:space_origin"] for v in by_class["TextLog"]] == [["events"]]
    assert [v["ViewBlueprint:space_origin"] for v in by_class["TextDocument"]] == [["legend"]]
    assert sorted(v["ViewBlueprint:display_name"][0] for v in by_class["TimeSeries"]) == sorted(PANELS)
    assert other["/time_panel"]["TimePanelBlueprint:timeline"] == ["sim_time"]
    tabs = {v["ContainerBlueprint:display_name"][0] for v in items.values() if "ContainerBlueprint:display_name" in v}
    assert {tab for tab, _ in PANELS.values()} <= tabs


def test_the_3d_view_has_the_window_height_beside_the_plots_log_and_colour_scale(recording):
    items, other = _blueprint(recording)
    root = items[str(uuid.UUID(bytes=bytes(other["/viewport"]["ViewportBlueprint:root_container"][0])))]
    assert root["ContainerBlueprint:container_kind"] == [rrb.components.ContainerKind.Horizontal.value]
    left, right = (items[path.split("/")[1]] for path in root["ContainerBlueprint:contents"])
    assert left["ViewBlueprint:class_identifier"] == ["3D"]
    assert right["ContainerBlueprint:container_kind"] == [rrb.components.ContainerKind.Vertical.value]
    tabs, notes = (items[path.split("/")[1]] for path in right["ContainerBlueprint:contents"])
    assert tabs["ContainerBlueprint:container_kind"] == [rrb.components.ContainerKind.Tabs.value]
    shown = {items[path.split("/")[1]]["ViewBlueprint:display_name"][0] for path in notes["ContainerBlueprint:contents"]}
    assert shown == {"controller log", "colour scale"}


def test_each_plot_shows_its_signal_and_a_legend_only_for_several_series(recording):
    items, _ = _blueprint(recording)
    store = RrdReader(recording).store()
    for view in items.values():
        if view.get("ViewBlueprint:class_identifier") != ["TimeSeries"]:
            continue
        title = view["ViewBlueprint:display_name"][0]
        origin = view["ViewBlueprint:space_origin"][0]
        selected = {c.entity_path for c in store.stream().filter(content=f"/{origin}/**", is_static=False)}
        assert selected == {f"/{origin}"}, title
        assert view["PlotLegend:visible"] == [PANELS[title][1]], title


def test_the_camera_is_the_one_given(recording):
    eye, target = blueprint_camera(recording)
    np.testing.assert_allclose(eye, CAMERA.eye, rtol=0, atol=1e-6)
    np.testing.assert_allclose(target, CAMERA.target, rtol=0, atol=1e-6)


def test_series_have_names_and_distinct_colours(recording):
    names = read_component(recording, "signals/pour/volume_mL", "SeriesLines:names").values[0].tolist()
    assert names == ["in pourer", "in catcher", "outside"]
    colors = read_component(recording, "signals/pour/volume_mL", "SeriesLines:colors").values[0]
    assert len(set(colors.tolist())) == 3


def test_the_colour_scale_is_stated(recording):
    text = read_component(recording, "legend", "TextDocument:text").values[0][0]
    assert text == colour_scale_text("viridis", 1.5, "A 2-D slice.")
    assert "0 to 1.5 m/s" in text and "`#440154` = 0 m/s" in text and text.endswith("A 2-D slice.")
