"""The default blueprint stored in the recording: a 3-D view of world, the phase log, one plot panel per signal
group whose contents select exactly that group's signals, and the sim_time timeline."""

from __future__ import annotations

import mujoco
import pytest
from rerun.chunk import RrdReader

from cosim.io.recording import PourRecorder
from cosim.io.rerun_read import read_component

SIGNALS = [
    "pourer/theta",
    "pourer/theta1",
    "slosh/h_q",
    "slosh/v_q",
    "volume/in_pourer",
    "volume/spilled",
    "wrench/pourer/force_z",
    "wrench/catcher/force_z",
    "joints/pour_arm/elbow.pos",
    "joints/pour_arm/elbow.vel",
    "joints/pour_arm/shoulder.pos",
    "joints/catch_arm/shoulder.vel",
]
# panel title -> the signals it must plot
PANELS = {
    "pourer": {"pourer/theta", "pourer/theta1"},
    "slosh": {"slosh/h_q", "slosh/v_q"},
    "volume": {"volume/in_pourer", "volume/spilled"},
    "wrench": {"wrench/pourer/force_z", "wrench/catcher/force_z"},
    "joints .pos": {"joints/pour_arm/elbow.pos", "joints/pour_arm/shoulder.pos"},
    "joints .vel": {"joints/pour_arm/elbow.vel", "joints/catch_arm/shoulder.vel"},
}
SINGLE_BODY = "<mujoco><worldbody><body name='cup'><joint type='hinge'/><geom type='box' size='.1 .1 .1'/></body></worldbody></mujoco>"


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    model = mujoco.MjModel.from_xml_string(SINGLE_BODY)
    path = tmp_path_factory.mktemp("blueprint") / "pour.rrd"
    with PourRecorder(path, model) as rec:
        for k in range(3):
            rec.log_scalars(0.01 * k, k, {name: float(k) for name in SIGNALS})
        rec.log_phase(0.0, 0, "SIM", "start")
    return path


def _blueprint(path) -> tuple[dict[str, dict], dict[str, list]]:
    """Views (id -> {class, name, origin, query}) and other blueprint entities (path -> components) of the file."""
    reader = RrdReader(path)
    (entry,) = reader.blueprints()
    views: dict[str, dict] = {}
    other: dict[str, dict] = {}
    for chunk in reader.store(store=entry).stream():
        batch = chunk.to_record_batch()
        columns = {n: batch.column(n).to_pylist()[-1] for n in batch.schema.names if ":" in n}  # components only
        parts = chunk.entity_path.strip("/").split("/")
        if parts[0] == "view":
            view = views.setdefault(parts[1], {})
            for key, column in [
                ("class", "ViewBlueprint:class_identifier"),
                ("name", "ViewBlueprint:display_name"),
                ("origin", "ViewBlueprint:space_origin"),
                ("query", "ViewContents:query"),
            ]:
                if column in columns:
                    view[key] = columns[column]
        else:
            other[chunk.entity_path] = columns
    return views, other


def test_views_of_the_default_blueprint(recording):
    views, other = _blueprint(recording)
    by_class: dict[str, list[dict]] = {}
    for view in views.values():
        by_class.setdefault(view["class"][0], []).append(view)
    (space,) = by_class["3D"]
    assert space["origin"] == ["world"] and space["query"] == ["$origin/**"]
    (log,) = by_class["TextLog"]
    assert log["origin"] == ["events"]
    assert sorted(v["name"][0] for v in by_class["TimeSeries"]) == sorted(PANELS)
    assert other["/time_panel"]["TimePanelBlueprint:timeline"] == ["sim_time"]


def test_each_plot_panel_selects_exactly_its_signals(recording):
    views, _ = _blueprint(recording)
    store = RrdReader(recording).store()
    for view in views.values():
        if view["class"] != ["TimeSeries"]:
            continue
        title = view["name"][0]
        selected = {c.entity_path for c in store.stream().filter(content=view["query"], is_static=False)}
        assert selected == {"/signals/" + name for name in PANELS[title]}, title


def test_series_are_labelled_without_their_group(recording):
    assert read_component(recording, "signals/joints/pour_arm/elbow.pos", "SeriesLines:names").values[0].tolist() == [
        "pour_arm/elbow.pos"
    ]
    assert read_component(recording, "signals/slosh/h_q", "SeriesLines:names").values[0].tolist() == ["h_q"]
