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
"""


def observations_page() -> str:
    """The page: the head, then a section per environment with a feature
    list (its table, :func:`iceenvs.observations.feature_table`), in the
    order of :data:`iceenvs.ENV_IDS`."""
    import gymnasium as gym

    from . import ENV_IDS
    from .observations import feature_table

    parts = [_HEAD]
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
