"""The hindcast section's runs: the example's files written where the report keeps its inputs,
an ensemble over field seeds on the example's scene, and the same scene without its field."""
import os
import re
import sys
from types import SimpleNamespace

import pytest

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from sections import hindcast  # noqa: E402

pytest.importorskip("netCDF4")


@pytest.mark.parametrize("quick", [True, False])
def test_the_hindcast_runs_its_own_files_over_seeds_and_once_in_open_water(tmp_path, quick):
    ctx = SimpleNamespace(quick=quick, out=str(tmp_path))
    runs = hindcast.plan(ctx)
    d = hindcast.inputs(ctx)
    for name in ("ocean.nc", "wind.csv", "chart.geojson", "hindcast.toml", "hindcast_open_water.toml"):
        assert os.path.exists(os.path.join(d, name)), name
    seeds = [r for r in runs if r.tag.startswith("hindcast_s")]
    assert len(seeds) == hindcast.SEEDS[quick]
    assert sorted({s for r in seeds for s in r.sets if s.startswith("run.seed=")}) == \
        [f"run.seed={hindcast.BASE_SEED + k}" for k in range(hindcast.SEEDS[quick])]
    water = [r for r in runs if r.tag == "hindcast_open_water"]
    assert len(water) == 1
    text = open(water[0].scenario).read()
    assert "[field]" not in text and not re.search(r"^chart\s*=", text, re.M)
    assert "[environment.current_file]" in text and "[environment.wind_file]" in text
    assert all(f"run.duration={hindcast.DURATION[quick]!r}" in r.sets for r in runs)
