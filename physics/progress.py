"""Progress bars for long runs of the engines."""
from __future__ import annotations

from collections.abc import Callable

__all__ = ["steps_with_bar"]


def steps_with_bar(step: Callable[[int], None], n: int, per: int, desc: str) -> None:
    """Call ``step(k)`` in chunks of at most ``per`` steps until ``n`` steps
    are done, with a tqdm bar counting the steps."""
    from tqdm.auto import tqdm

    per = max(1, int(per))
    with tqdm(total=n, unit="step", desc=desc, dynamic_ncols=True) as bar:
        left = n
        while left > 0:
            k = min(per, left)
            step(k)
            left -= k
            bar.update(k)
