"""Versions of the weight-free perception backends, in one light module so the stage descriptor can
name them without importing the backends (Open3D, OpenCV)."""

# 2: frame-and-panel fronts, rims, drawer_max_h 0.45; 3: fronts from the colour frames; 4: sliding doors;
# 5: straight seams by line median, handle shadows filled, texture-adaptive clutter
HEURISTIC_VERSION = "5"
# 2: says "sliding" for GT prismatic joints in the part's front plane
ORACLE_VERSION = "2"
