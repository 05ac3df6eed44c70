"""rsibr.compare reports the numbers `rsibr compare --json` reports."""
import json

import numpy as np

import rsibr
from conftest import random_map_set


def test_compare_gives_the_numbers_of_the_command_line(tmp_path, cli):
    rng = np.random.default_rng(21)
    a = random_map_set(rng, "icosa", size=16)
    b = rsibr.MapSet([rsibr.MapView(v.rgb * np.float32(1.7) + rng.uniform(0, 0.1, v.rgb.shape).astype(np.float32),
                                    v.view) for v in a])
    rsibr.write_map_set(str(tmp_path / "a.exr"), a)
    rsibr.write_map_set(str(tmp_path / "b.exr"), b)
    cli("compare", tmp_path / "a.exr", tmp_path / "b.exr", "--json", tmp_path / "c.json", "-q")
    j = json.loads((tmp_path / "c.json").read_text())
    c = rsibr.compare(rsibr.read_map_set(str(tmp_path / "a.exr")), rsibr.read_map_set(str(tmp_path / "b.exr")))
    for when, ours in [("before", c.before), ("after", c.after)]:
        for key in ["relative_rms", "log_rms_stops", "psnr_db", "mse"]:
            assert getattr(ours, key) == j["overall"][when][key]
    assert list(c.fit.gains) == j["fit"]["gains"]
    assert abs(c.fit.exposure_stops - np.log2(1.7)) < 0.05  # the fit finds the gain
    assert [p.name for p in c.pairs] == [v["name"] for v in j["views"]]
    assert c.pairs[4].after.relative_rms == j["views"][4]["after"]["relative_rms"]


def test_an_environment_compared_with_itself_has_no_error():
    env = rsibr.Environment(np.random.default_rng(1).uniform(0.1, 2, (16, 32, 3)).astype(np.float32), "latlong")
    c = rsibr.compare(env, env)
    assert c.before.relative_rms == 0 and c.before.log_rms_stops == 0 and c.before.psnr_capped
