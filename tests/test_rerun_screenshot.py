"""``python -m cosim.tools.screenshot``: bad input is one line and exit 2 with nothing written; the viewer URL opens
the recording the script serves."""

from __future__ import annotations

import urllib.parse

import pytest

from cosim.tools import screenshot


@pytest.mark.parametrize(
    "args, message",
    [
        (["missing.rrd"], "recording: no file at"),
        (["{rrd}", "--size", "10x10"], "--size"),
        (["{rrd}", "--size", "wide"], "--size"),
        (["{rrd}", "--poll", "0"], "--poll: must be in (0, 60]"),
        (["{rrd}", "--timeout", "-1"], "--timeout: must be in (0, 3600]"),
        (["{rrd}", "--settle", "0"], "--settle: must be in (0, 600]"),
        (["{rrd}", "--out", "{tmp}/no/such/folder/x.png"], "--out: folder"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, args, message):
    rrd = tmp_path / "pour.rrd"
    rrd.write_bytes(b"")
    argv = [a.format(rrd=rrd, tmp=tmp_path) for a in args]
    if "--out" not in argv:
        argv += ["--out", str(tmp_path / "shot.png")]
    with pytest.raises(SystemExit) as exit_:
        screenshot.main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert message in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pour.rrd"]


def test_the_viewer_url_names_the_served_recording():
    url = urllib.parse.urlsplit(screenshot.viewer_url(9090, 9876))
    assert (url.hostname, url.port) == ("127.0.0.1", 9090)
    assert urllib.parse.parse_qs(url.query)["url"] == ["rerun+http://127.0.0.1:9876/proxy"]
