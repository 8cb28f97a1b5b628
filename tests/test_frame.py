"""core.project.frame.GeorefFrame: georef/transform.json read once, typed (issue 35)."""
import json
import os

import numpy as np
import pytest

from core.geometry.similarity import Similarity
from core.georef.results import GeorefResult
from core.project.frame import FrameError, GeorefFrame
from core.project.layout import Layout, LayoutError
from core.project.workspace import Workspace


def test_frame_reads_what_georef_writes(tmp_path):
    offset = np.array([500123.5, 4600456.25, 312.0])
    m2l = Similarity(2.5, np.eye(3), np.array([1.0, -2.0, 3.0]))
    res = GeorefResult(reconstruction=None, crs="EPSG:32633", offset=offset, model_to_local=m2l, source="gcp",
                       adjusted=True)
    paths = res.save(str(tmp_path))
    with open(paths["transform.json"], encoding="utf-8") as fh:
        frame = GeorefFrame.from_dict(json.load(fh), paths["transform.json"])
    assert frame.crs == "EPSG:32633" and frame.source == "gcp" and frame.adjusted is True
    np.testing.assert_allclose(frame.offset, offset)
    np.testing.assert_allclose(frame.model_to_local.apply([1.0, 1.0, 1.0]), m2l.apply([1.0, 1.0, 1.0]))
    local = np.array([[1.0, 2.0, 3.0], [-4.0, 5.0, 6.0]])
    np.testing.assert_allclose(frame.to_local(frame.to_world(local)), local)
    np.testing.assert_allclose(frame.to_world(local)[0], offset + local[0])


@pytest.mark.parametrize("doc, what", [([1, 2], "JSON object"), ({"offset": [1, 2]}, "three numbers"),
                                       ({"offset": [1, None, 3]}, "finite"), ({"offset": "abc"}, "three numbers")])
def test_bad_transform_named(doc, what):
    with pytest.raises(FrameError, match=what) as e:
        GeorefFrame.from_dict(doc, "/ws/georef/transform.json")
    assert "/ws/georef/transform.json" in str(e.value)


def test_oldest_transform_has_crs_and_offset_only():
    frame = GeorefFrame.from_dict({"crs": "EPSG:2180", "offset": [1, 2, 3]})
    assert frame.model_to_local is None and frame.adjusted is None and frame.crs == "EPSG:2180"


def test_layout_names_missing_transform(tmp_path):
    ws = Workspace.create_or_open(str(tmp_path / "ws"))
    with pytest.raises(LayoutError, match="transform.json is missing"):
        Layout(ws).load_transform()
    os.makedirs(os.path.dirname(Layout(ws).transform_json), exist_ok=True)
    with open(Layout(ws).transform_json, "w", encoding="utf-8") as fh:
        fh.write('{"crs": "EPSG:32633", "offset": [1, 2]}')
    with pytest.raises(FrameError, match="three numbers"):
        Layout(ws).load_transform()
