"""The observation entries of every environment as one Markdown page,
``docs/observations.md``: ``python -m iceenvs.observation_page`` writes it
from the environments' own feature lists, and a test checks that the
committed page is what the code gives, so that the page is there to read
without building the site.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["observations_page", "PAGE", "main"]

#: the committed page, relative to the checkout
PAGE = Path("docs/observations.md")

_HEAD = """\
# Observations

<!-- Written by `python -m iceenvs.observation_page`; a test checks it against the code. -->

The vector observation of each environment, entry by entry, as its class
builds it: the entry's index and name, what it measures, the unit of the raw
value (which `info["physics"]` holds under the same name, in SI units), how
the vector scales it, and the bounds of the scaled value, into which it is
clipped. The scalings are those of `iceenvs/observations.py` ("log force",
for instance, is sign(F) log10(1 + |F| / 1 N)). Signs follow the ship frame:
x forward, y to port, angles anticlockwise. `horizon=N` appends `time_left`,
the remaining fraction of an N-step episode.

A policy reads an entry by name:

```python
import gymnasium as gym
import iceenvs  # noqa: F401

env = gym.make("iceenvs/ShipNavigation-v1")
names = [f.name for f in env.unwrapped.features]
obs, info = env.reset(seed=0)
print(names.index("goal_sin"), obs[names.index("goal_sin")])
env.close()
```

The lidar of the ship environments (`lidar_distance_k`,
`lidar_concentration_k`) looks over the half plane ahead of the ship: its
K sectors (`lidar_sectors`: 9 in ShipNavigation-v0 and ShipBeset-v0, 15 in
ShipNavigation-v1) split the field of view of 180° centred on the heading
into equal wedges, counted anticlockwise seen from above. Sector 0 is to
starboard: its central ray points heading − 90° + (k + ½) · 180° / K for
sector k, so sector 0 looks 80° to starboard with 9 sectors (84° with 15),
the middle sector (4 of 9, 7 of 15) straight ahead and the last one as far
to port.

## The costmap (ship environments)

`obs_type="costmap"` gives every ship environment an observation for a
convolutional policy: a map of the ice that the lattice planner costs
(`agents.planners.LatticePlanner`), `Box(float32, (3, rows, cols))`;
`obs_type="costmap_dict"` gives `Dict({"costmap": ..., "vector": ...})`,
the map beside the default vector. Both work in the native vector
environments. `iceenvs.costmap` builds it, with one compiled kernel that
the planner shares.

**The grid.** It lies in the channel frame: x along the channel towards the
goal line, y across it, to port. Cells of `costmap_cell` (5 m) reach from
`costmap_behind` (20 m) behind the ship's centroid to `costmap_ahead`
(300 m) ahead of it, and across the channel's width, centred on the ship's
y: 64 × 40 cells in ShipNavigation-v1 (channel 200 m wide), 64 × 30 in
ShipNavigation-v0. Row 0 is the farthest ahead and column 0 the farthest to
port: drawn with row 0 at the top, the map is the ice seen from above with
the goal direction up and port to the left. The centre of the cell of row
i and column j is x = x_ship + ahead − (i + ½) · cell, y = y_ship +
cols · cell / 2 − (j + ½) · cell. The grid does not turn with the ship;
the vector holds its heading.

**The channels.**

0. `impulse`: the planner's cost density c [N s/m]. Each floe's expected
   collision impulse J [N s] (a head-on hit at the ship's full speed,
   `expected_impulses`) is spread as a cone over the disc of radius
   R = r + B/2 about its centre (r its radius, B the beam):
   c = J (1 − ρ / R) / R at distance ρ from the centre, so that a route
   through the centre meets J and a glancing one less. The densities of the
   floes add up, averaged over 2 × 2 samples of each cell (2.5 m apart;
   the samples are at most 2.5 m apart for any cell). Stored as
   log(1 + c / 12 500 N s/m), clipped at 10: about 0 to 3 in v1's fields.
1. `outside_channel`: 1 where the cell's centre lies outside the channel,
   more than channel_width / 2 from its centre line across, else 0.
2. `beyond_goal`: 1 where the cell's centre lies past the goal line,
   x > goal_x, else 0.

The scale 12 500 N s/m is the ice impulse that one metre sailed is worth in
ShipNavigation-v1's reward, so a cell of value log 2 ≈ 0.69 costs a route
through it as much in ice as in time. Summing c · cell down a column
approximates the impulse that a straight route there would meet. The map is
a sensor: only floes whose enlarged disc reaches into it count. ShipNavigation-v1's
channel is periodic across, so the map shows the ice beyond its edges
through the floes' periodic images, as the swath sensor sees it, and channel
1 says where the channel ends. {costmap_cost}

```python
import gymnasium as gym
import iceenvs  # noqa: F401

env = gym.make("iceenvs/ShipNavigation-v1", obs_type="costmap")
obs, info = env.reset(seed=0)
print(obs.shape, env.observation_space.shape)   # (3, 64, 40) twice
env.close()
```

The picture shows a small ShipNavigation-v1 after a turn to port: the frame
that follows the ship over the costmap's reach, then channel 0 and the masks,
turned the same way (x to the right, port up). It is written by

```bash
python -m iceenvs.costmap --out docs/figures/costmap
```

![The costmap of ShipNavigation-v1 beside the ice it shows](figures/costmap/costmap.png)
"""


#: the sensors benchmark's record (``seaice bench sensors``), from which the
#: page states what the costmap costs
SENSORS_RECORD = Path(__file__).resolve().parent.parent / "docs" / "benchmarks" / "sensors.json"


def costmap_cost(record: Path = SENSORS_RECORD) -> str:
    """The page's sentence on what making the costmap costs, from the
    sensors benchmark's record (a pointer to the command where there is
    none)."""
    import json

    data = json.loads(record.read_text(encoding="utf-8")) if record.is_file() else None
    rows = data["data"]["rows"] if data else []
    if not rows or not all("costmap" in r and "costmap_far" in r for r in rows):
        return ("What making the map costs, beside a step, is timed by "
                "`seaice bench sensors`.")
    near = [r["costmap"] / r["step"] for r in rows]
    far = [r["costmap_far"] / r["step"] for r in rows]
    spread = [r["concentration"] for r in rows]
    cpu = data["machine"].get("cpu", "this machine")

    def span(values):
        lo, hi = min(values), max(values)
        return f"{lo:.2f}" if f"{lo:.2f}" == f"{hi:.2f}" else f"{lo:.2f}–{hi:.2f}"

    return (f"Making the map costs {span(near)} of a step of ShipNavigation-v1 "
            f"(A = {min(spread):g}–{max(spread):g}), and {span(far)} with it reaching 500 m "
            f"ahead (`seaice bench sensors`, on the Benchmarks page; {cpu}, "
            f"{data['date'][:10]}).")


def observations_page() -> str:
    """The page: the head, then a section per environment with a feature
    list (its table, :func:`iceenvs.observations.feature_table`), in the
    order of :data:`iceenvs.ENV_IDS`."""
    import gymnasium as gym

    from . import ENV_IDS
    from .observations import feature_table

    parts = [_HEAD.replace("{costmap_cost}", costmap_cost())]
    for env_id in ENV_IDS:
        env = gym.make(env_id)
        try:
            features = getattr(env.unwrapped, "features", None)
            size = env.observation_space.shape
        finally:
            env.close()
        parts.append(f"## {env_id}\n")
        if features is None:
            parts.append(f"A vector of {size[0]} entries; its class docstring describes them "
                         f"(`help(gym.make(\"{env_id}\").unwrapped)`).\n")
            continue
        parts.append(f"{len(features)} entries (`obs_type=\"vector\"`, the default).\n")
        parts.append(feature_table(features) + "\n")
    return "\n".join(parts)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m iceenvs.observation_page",
                                description="Write the observation page of every environment.")
    p.add_argument("--out", type=Path, default=PAGE, help=f"the page ({PAGE})")
    args = p.parse_args(argv)
    args.out.write_text(observations_page(), encoding="utf-8")
    print(f"written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
