"""numpy's BLAS kept to one thread while the physics steps on several.

numpy's wheels bring OpenBLAS, which runs a matrix product on a thread per core and
keeps those threads spinning for a while after each one, waiting for the next. Our
products are tiny (a few thousand 3-vectors against 96 directions when the sandbox
frames a crowd, 3 x 3 rotations): one thread does them as fast, and the spinning ones
take the core a physics stepping thread needs. Measured with the sandbox framing 64
creatures on rocky ground (`tools/bench_sandbox.py`, 2 cores): 35 ms a physics frame
with BLAS on two threads, 27-30 ms with one.

`quiet_blas()` (called when a world steps on more than one thread) limits BLAS to one
thread for the process, unless the user chose for themselves with
`OPENBLAS_NUM_THREADS`, `OMP_NUM_THREADS` or `MKL_NUM_THREADS`. Each call limits every
BLAS loaded by then: scipy, imported where it is used, brings its own OpenBLAS, which a
world built after it finds and limits too (no frame calls scipy's BLAS).
"""

from __future__ import annotations

import os

from threadpoolctl import threadpool_limits

CHOSEN_BY_USER = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def quiet_blas() -> bool:
    """Limit every BLAS loaded so far to one thread; False if the user chose a number."""
    if any(name in os.environ for name in CHOSEN_BY_USER):
        return False
    threadpool_limits(limits=1, user_api="blas")
    return True
