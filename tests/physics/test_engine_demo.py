"""The engine demo (``python -m physics.demo``): a pack that the wind has
pressed on a wall and brought to rest is held by the wall with the wind's
force, and the figures and the command work on tiny runs."""
from __future__ import annotations

import numpy as np
import pytest

import physics.demo as demo
from physics.demo import (chain_samples, chain_width, draw, draw_transit, error_meaning,
                          force_chains, main, ship_transit, wall_force, wind_force)


def test_walls_hold_the_wind_force_once_the_pack_is_at_rest():
    sim = force_chains(60, 0.8, 20.0, seed=1)
    # The pack settles within minutes, but when its last floe stops depends on a last
    # rearrangement that the rounding of the machine's arithmetic can shift (after 300 s one
    # floe still moved at 4 cm/s on one machine, none faster than 1 cm/s on another), so it
    # is given up to 10 minutes. At rest: the fastest floe creeps at under 1 cm/s (against
    # ~0.7 m/s of free drift at 20 m/s)
    sim.advance(300.0)
    while sim.time < 600.0 and np.hypot(*sim.velocities.T).max() >= 0.01:
        sim.advance(50.0)
    speed = np.hypot(*sim.velocities.T)
    assert speed.max() < 0.01
    c = sim.contacts()
    assert 2 * len(c) / sim.n_floes > 2.0           # jammed: chains, not scattered pairs
    push, back = wind_force(sim), wall_force(sim)
    assert push[0] > 0 and push[1] == 0             # the wind blows along +x
    # a pack at rest has no net force, so the walls (the sum of all contact
    # forces: the floe-floe ones cancel pairwise) cancel the wind; 3 %: the
    # water drag and inertia of the floes still creeping (1.1 % measured)
    assert abs(back[0] + push[0]) < 0.03 * push[0]
    assert abs(back[1]) < 0.03 * push[0]


def test_force_network_and_transit_figures_are_written(tmp_path):
    sim = force_chains(30, 0.7, 20.0, seed=2)
    sim.advance(2.0)
    draw(sim, tmp_path / "chains.png", "30 floes")
    sim = ship_transit(seed=1)
    sim.advance(60.0)                               # the bow meets the ice at about 31 s
    assert len(sim.ship.collisions()["floe"]) > 0
    draw_transit(sim, tmp_path / "transit.png", "transit")
    for name in ("chains.png", "transit.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_chain_legend_samples_are_round_forces_up_to_the_largest():
    assert chain_samples(5300.0) == [5000.0, 1000.0, 200.0]
    assert chain_samples(1.0) == [1.0, 0.2, 0.05]
    for largest in (7.3, 980.0, 2.1e6):
        samples = chain_samples(largest)
        assert 2 <= len(samples) <= 3 and samples[0] <= largest
        assert all(b < a for a, b in zip(samples, samples[1:]))
    widths = chain_width(np.array([0.0, 500.0, 1000.0]), 1000.0)
    assert widths[0] > 0 and widths[2] - widths[1] == pytest.approx(widths[1] - widths[0])


def kept_figures(monkeypatch):
    """The figures the demo draws, kept instead of saved."""
    figures = []
    monkeypatch.setattr(demo, "_save", lambda fig, path: figures.append(fig))
    return figures


def texts(fig):
    return [t.get_text() for t in fig.findobj(lambda a: hasattr(a, "get_text"))]


def test_force_chain_figure_shows_the_wind_the_walls_and_what_a_width_means(monkeypatch):
    figures = kept_figures(monkeypatch)
    sim = force_chains(30, 0.8, 12.0, seed=2)
    sim.advance(40.0)                               # the floes have met (about 25 s)
    assert len(sim.contacts()) > 0
    draw(sim, "chains.png", "30 floes")
    words = texts(figures[0])
    assert "wind 12 m/s" in words
    assert "rigid wall" in words
    assert any(w.startswith("contact force") and w.endswith("N") for w in words)
    assert any("∝ normal force" in w for w in words)


def test_transit_figure_says_what_the_error_of_the_mean_resistance_is(monkeypatch):
    assert "standard error of the mean" in error_meaning(500)
    assert "20 consecutive time blocks" in error_meaning(500)
    assert "7 consecutive" in error_meaning(7)
    figures = kept_figures(monkeypatch)
    sim = ship_transit(seed=1)
    sim.advance(60.0)
    draw_transit(sim, "transit.png", "transit")
    label = next(w for w in texts(figures[0]) if w.startswith("mean resistance"))
    assert "±" in label and "standard error of the mean" in label


def test_command_prints_the_contacts_and_draws_both_figures(tmp_path, capsys):
    assert main(["--floes", "30", "--concentration", "0.7", "--duration", "2",
                 "--ship-duration", "2", "--no-progress", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "per floe" in out and "force balance" in out and "Ship transit" in out
    for name in ("force_chains.png", "ship_transit.png"):
        assert (tmp_path / name).stat().st_size > 10_000


@pytest.mark.parametrize("args, words", [
    (["--floes", "5"], ["--floes", "5"]),
    (["--concentration", "0.95"], ["--concentration", "0.95"]),
    (["--wind", "0"], ["--wind", "0"]),
    (["--ship-duration", "-1"], ["--ship-duration", "-1"]),
    (["--floes", "10", "--concentration", "0.9"], ["--floes 10 --concentration 0.9"]),
])
def test_bad_arguments_are_refused_with_their_value(args, words, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    for word in words:
        assert word in err
    assert not any(tmp_path.iterdir())
