"""Duplicate removal (paper Sec. "Interactive scene integration"), with a bounded stage 2.

The stage lives in :mod:`.remove`; this package names it and its version."""

from ..stage import StageSpec
from .remove import dedup_indices, remove_duplicates

STAGE_VERSION = "6"  # 2: stage 3 removes fragments; 3: stage 4 removes slivers inside a larger part's box; 4: stage 5 merges same-motion pieces; 5: stage 6 cuts a mask merged around a smaller front back off it; 6: bridges, scraps, cut parts deduped again
STAGE = StageSpec("dedup", __name__, STAGE_VERSION, sections=("dedup",), upstream=("articulation",))

__all__ = ["STAGE", "STAGE_VERSION", "dedup_indices", "remove_duplicates"]
