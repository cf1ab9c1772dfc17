"""A team of threads that stays inside one ``prange`` region for many steps.

A ``prange`` loop costs about 1–2.5 µs to start and join on two threads of
a shared machine, more when the waiting threads have gone to sleep. A Hertz
step of 20000 loose floes takes about 40 µs on two threads and needs two
such regions (the kick–drift pass and the pair loop), so this overhead is a
tenth of the step. Here the threads enter one region for a run of steps
and meet between phases at a spin barrier instead.

The barrier cannot deadlock, however the runtime schedules the iterations
of ``prange(n_threads)``: every phase is a set of tasks (one or more per
thread), each task is claimed by exactly one thread with an atomic
compare-and-swap, and a thread first does its own tasks and then claims
any task that nobody has claimed yet (:func:`task_order`) before it waits
for the phase to be complete. If only one thread ever runs, it does every
task itself and never waits for another. So a thread normally keeps its
own floes in its own caches from step to step, and a thread that is late
(a busy host, a slow core) only loses some of its tasks to the others.

Phases are numbered 1, 2, 3, ... (generations). ``sync`` is an int64 array
of ``sync_size(n_tasks)`` zeros at the start of a run: ``sync[k]`` is the
last generation in which task k was claimed, ``sync[n_tasks]`` counts the
tasks done so far (generation g is complete when g * n_tasks tasks are
done), and ``sync[n_tasks + 1]`` is a token that one thread takes to write
the results of the run. Phases of different kinds with different numbers
of tasks (the kick–drift pass and the pair loop of a step) keep a ``sync``
array and a generation count each.

A phase is complete when its tasks are done, not when every thread has
arrived: a thread that was held up may find the others already a phase or
more ahead. Data that every thread reads outside a task (the partial
results of the kick pass, say) may then have been overwritten by the next
phase. :func:`overtaken` tells a thread that has read such data whether
this happened; if so, the thread leaves the team and the others finish the
run without it.
"""
from __future__ import annotations

import platform

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic


def _is_int64_array(arr):
    return isinstance(arr, types.Array) and arr.dtype == types.int64


def _item_pointer(context, builder, arr_type, arr, idx):
    ary = context.make_array(arr_type)(context, builder, arr)
    return cgutils.get_item_pointer(context, builder, arr_type, ary, [idx], wraparound=False)


@intrinsic
def atomic_add(typingctx, arr, idx, value):
    """arr[idx] += value as one atomic operation (sequentially consistent;
    int64 arrays). Returns the old value."""
    if not _is_int64_array(arr):
        return None

    def codegen(context, builder, signature, args):
        ptr = _item_pointer(context, builder, signature.args[0], args[0], args[1])
        val = context.cast(builder, args[2], signature.args[2], types.int64)
        return builder.atomic_rmw("add", ptr, val, "seq_cst")
    return types.int64(arr, types.intp, types.int64), codegen


@intrinsic
def atomic_load(typingctx, arr, idx):
    """arr[idx] read as one atomic operation with acquire order: every
    write that another thread made before its (release or stronger) atomic
    write of the value read is visible afterwards."""
    if not _is_int64_array(arr):
        return None

    def codegen(context, builder, signature, args):
        ptr = _item_pointer(context, builder, signature.args[0], args[0], args[1])
        return builder.load_atomic(ptr, "acquire", 8)
    return types.int64(arr, types.intp), codegen


@intrinsic
def atomic_cas(typingctx, arr, idx, expected, new):
    """If arr[idx] == expected, set it to ``new`` (one atomic operation,
    sequentially consistent). Returns whether it did."""
    if not _is_int64_array(arr):
        return None

    def codegen(context, builder, signature, args):
        ptr = _item_pointer(context, builder, signature.args[0], args[0], args[1])
        exp = context.cast(builder, args[2], signature.args[2], types.int64)
        new_ = context.cast(builder, args[3], signature.args[3], types.int64)
        pair = builder.cmpxchg(ptr, exp, new_, "seq_cst", "seq_cst")
        return builder.extract_value(pair, 1)
    return types.boolean(arr, types.intp, types.int64, types.int64), codegen


_X86 = platform.machine().lower() in ("x86_64", "amd64", "i386", "i686")


@intrinsic
def spin_pause(typingctx):
    """A hint to the processor that this thread is spinning (``pause`` on
    x86; nothing elsewhere). It saves power and, on a virtual machine, lets
    the hypervisor see the spin and run the thread being waited for."""
    def codegen(context, builder, signature, args):
        if _X86:
            fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), []),
                                                "llvm.x86.sse2.pause")
            builder.call(fn, [])
        return context.get_dummy_value()
    return types.none(), codegen


@njit(cache=True)
def sync_size(n_tasks):
    """Length of the ``sync`` array of a team with ``n_tasks`` tasks per phase."""
    return n_tasks + 2


@njit(cache=True, inline="always")
def task_order(t, m, n_threads, n_tasks):
    """The m-th task (m = 0 … n_tasks − 1) that thread t tries to claim in
    a phase of ``n_tasks`` tasks shared by ``n_threads`` threads: first its
    own consecutive block (t·n/T up to (t+1)·n/T, in order), then the
    others from the end of the block before its own backwards, wrapping
    round. Every task appears once. A thread thus keeps the same floes
    from step to step, and a thread that is done early takes over the
    tasks that the thread before it would reach last."""
    lo = t * n_tasks // n_threads
    own = (t + 1) * n_tasks // n_threads - lo
    if m < own:
        return lo + m
    return (lo - 1 - (m - own)) % n_tasks


@njit(cache=True, inline="always")
def claim(sync, task, generation):
    """Claim ``task`` for ``generation``: True for exactly one caller."""
    return atomic_cas(sync, task, generation - 1, generation)


@njit(cache=True, inline="always")
def task_done(sync, n_tasks):
    """Count one task of the current generation as done."""
    atomic_add(sync, n_tasks, 1)


@njit(cache=True, inline="always")
def wait_generation(sync, n_tasks, generation):
    """Spin until every task of ``generation`` is done. Call only after
    trying to claim every task of the generation (so that it cannot wait
    for a task nobody will do)."""
    target = generation * n_tasks
    while atomic_load(sync, n_tasks) < target:
        spin_pause()


@njit(cache=True, inline="always")
def overtaken(sync, n_tasks, last_safe):
    """Whether any task of a generation after ``last_safe`` has been
    claimed. Call it after reading data that the tasks of generation
    last_safe + 1 (and later) write: if False, the reads saw the data as the
    earlier generations left it (the check is a full memory barrier, so the
    reads cannot be moved past it). If True, they may be torn, and the
    caller must leave the team."""
    for k in range(n_tasks):
        if atomic_add(sync, k, 0) > last_safe:
            return True
    return False


@njit(cache=True, inline="always")
def take_token(sync, n_tasks):
    """True for exactly one caller per run: the thread that writes the
    results of the run."""
    return atomic_cas(sync, n_tasks + 1, 0, 1)
