"""An atomic fetch-and-add for compiled code: dynamic scheduling of
``prange`` loops.

Numba splits a ``prange`` loop into equal static blocks, one per thread. On
a machine whose cores run at different speeds at the same moment (a
virtual machine sharing its host, a laptop with efficiency cores), the
fast thread then waits for the slow one at the end of every loop. With
:func:`fetch_add` the threads instead claim chunks of work one at a time
from a shared counter, so each does as much as its speed allows::

    claimed = np.zeros(1, np.int64)
    for _ in prange(numba.get_num_threads()):   # one worker per thread
        while True:
            c = fetch_add(claimed, 0, 1)         # next unclaimed chunk
            if c >= n_chunks:
                break
            ...                                  # work on chunk c only

Each chunk is claimed exactly once whatever the timing, so results written
per chunk (never per worker) are the same bit for bit in every run.
"""
from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def fetch_add(typingctx, counter, index, value):
    """``old = counter[index]; counter[index] += value; return old`` as one
    atomic operation (sequentially consistent) on a 1-d int64 array. No
    bounds check: ``index`` must be valid."""
    if not (isinstance(counter, types.Array) and counter.ndim == 1
            and counter.dtype == types.int64 and isinstance(index, types.Integer)
            and isinstance(value, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        array_type = sig.args[0]
        array = context.make_array(array_type)(context, builder, args[0])
        where = context.cast(builder, args[1], sig.args[1], types.intp)
        ptr = cgutils.get_item_pointer(context, builder, array_type, array, [where],
                                       wraparound=False)
        step = context.cast(builder, args[2], sig.args[2], types.int64)
        return builder.atomic_rmw("add", ptr, step, "seq_cst")

    return types.int64(counter, index, value), codegen
