"""Rasterization of the scan mesh per frame: triangle-id buffer and depth (occlusion-correct)."""

from .rasterizer import RasterResult, Rasterizer

__all__ = ["RasterResult", "Rasterizer"]
