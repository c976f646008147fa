"""Ground-truth I/O (Articulate3D)."""

from .articulate3d import GTPart, GroundTruth, read_articulate3d, write_articulate3d

__all__ = ["GTPart", "GroundTruth", "read_articulate3d", "write_articulate3d"]
