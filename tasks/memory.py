"""Process memory settings for conversion workers.

glibc gives each thread that contends for the allocator its own heap ("arena", up to 8 per core), and
memory freed in one arena is not reused by another: with the flow's thread pool, the numpy buffers of
perception, fusion and export spread over several arenas and the resident size grows with them. Two
arenas cut the ScanNet++-sized benchmark's peak from 4.74 to 3.45 GB at the same wall time
(``benchmarks/bench_scannetpp.py``).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import sys

M_ARENA_MAX = -8  # glibc's mallopt parameter number


def limit_malloc_arenas(default: int = 2) -> bool:
    """Cap glibc's malloc arenas for the rest of this process (``REACT3D_MALLOC_ARENAS``, default 2;
    0 leaves glibc's default). A ``MALLOC_ARENA_MAX`` the user set is left alone. True when applied."""
    if not sys.platform.startswith("linux") or "MALLOC_ARENA_MAX" in os.environ:
        return False
    try:
        n = int(os.environ.get("REACT3D_MALLOC_ARENAS", default))
    except ValueError:
        return False
    if n <= 0:
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        return bool(libc.mallopt(M_ARENA_MAX, n))
    except (OSError, AttributeError):  # not glibc (musl has no mallopt): nothing to cap
        return False
