"""Rasterization of the scan mesh per frame: triangle-id buffer and depth (occlusion-correct)."""

from .rasterizer import RasterResult, Rasterizer, RayHits, pixel_rays

__all__ = ["RasterResult", "Rasterizer", "RayHits", "pixel_rays"]
