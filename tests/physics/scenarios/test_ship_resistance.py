"""The ship-resistance scenario: a small sweep writes its points, the
resistance rises with concentration and with speed (where Zuev's law and
Huang et al.'s fit agree on the sign: both rise with both), the fields are
paired across the points, and the summary and the figure set the laws
beside the points."""
from __future__ import annotations

import math

import numpy as np
import pytest

xr = pytest.importorskip("xarray")
pytest.importorskip("yaml")
pytest.importorskip("matplotlib")

from physics.ice_resistance import zuev_resistance
from physics.scenarios import run_scenario
from physics.scenarios.ship_resistance import (ShipResistance, field_seed, froude_speed,
                                               law_values, resistance_points,
                                               transit_parameters)

# one hull, one size law, concentrations 0.2 and 0.6, Fr_h 0.25 and 1, two fields
SMALL = dict(hulls="psv", size_laws="auto_icenav", concentrations=[0.2, 0.6],
             froude_numbers=[0.25, 1.0], fields=2, band_length=200.0, channel_width=210.0,
             output_interval=2.0)


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("resistance") / "run"
    res = run_scenario("ship-resistance", overrides=SMALL, out=out, workers=1,
                       progress=False, log=lambda *a: None)
    with xr.open_dataset(res.dataset) as ds:
        return res, ds.load()


def test_the_sweep_writes_every_point(small_run):
    res, ds = small_run
    assert ds.sizes["case"] == 8
    assert np.all(ds["completed"].values == 1)
    assert np.all(np.isfinite(ds["resistance"].values) & (ds["resistance"].values > 0))
    # prescribed: the ship holds the speed of its Froude number on the 1.5 m ice
    assert np.allclose(ds["speed_loss"].values, 0.0, atol=1e-9)
    assert froude_speed(1.0) == pytest.approx(math.sqrt(9.81 * 1.5), rel=1e-12)
    assert [f.name for f in res.figures] == ["resistance_zuev.png", "resistance_huang.png"]


def test_resistance_rises_with_concentration_and_speed(small_run):
    """Zuev's law and Huang et al.'s fit both rise with S and with v; so must
    the model, field by field (the fields are the same draw at each point)."""
    _, ds = small_run
    (g,) = resistance_points(ds)
    assert g["fields"] == 2
    r = g["mean"]                                     # (S: 0.2, 0.6) × (Fr_h: 0.25, 1)
    assert np.all(r[1, :] > r[0, :]), r
    assert np.all(r[:, 1] > r[:, 0]), r
    zuev, huang = law_values(g, g["concentration"], g["speed"])
    for law in (zuev, huang):
        assert np.all(law[1, :] > law[0, :]) and np.all(law[:, 1] > law[:, 0])


def test_the_summary_sets_the_laws_beside_the_points(small_run):
    _, ds = small_run
    from physics.scenarios.runner import find_config

    p = find_config("ship-resistance").resolve(SMALL)
    rows = ShipResistance().summarise(ds, p)
    quantities = [q for q, _, _ in rows]
    assert any("exponent b of R = a S^b" in q for q in quantities)
    assert any("exponent b of R = a v^b" in q for q in quantities)
    assert any("R / Zuev's R" in q for q in quantities)
    # no point of this sweep is at the tasks' speeds (Fr_h 0.25 and 1 only)
    (task,) = [r for r in rows if "ShipNavigation tasks'" in r[0]]
    assert task[1] == "—; —; —"
    (g,) = resistance_points(ds)
    assert law_values(g, [0.5], [2.0])[0][0, 0] == pytest.approx(
        zuev_resistance(2.0, 0.5, 18.0, 1.5), rel=1e-12)


def test_cases_fields_and_parameters():
    from physics.scenarios.runner import find_config

    p = find_config("ship-resistance").resolve({})
    cases = ShipResistance().cases(p)
    assert len(cases) == 2 * 2 * 7 * 4 * 5
    assert {c["field"] for c in cases} == set(range(5))
    assert field_seed(0, 3) == field_seed(0, 3) != field_seed(0, 4)
    brash = transit_parameters(p, {"hull": 1, "size_law": 1})
    assert brash["hull"] == "research" and brash["sizes"] == "lognormal"
    assert brash["lognormal_median"] == p["brash_median"]
    assert transit_parameters(p, {"hull": 0, "size_law": 0})["sizes"] == "auto_icenav"
    with pytest.raises(ValueError, match="cannot hold AUTO-IceNav's largest floes"):
        ShipResistance().cases(dict(p, channel_width=200.0))
