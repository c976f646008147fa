"""REACT3D core: the pure geometric library (no Prefect, no model weights, no network).

One sub-package per pipeline stage; see DESIGN.md for the stage list.
"""

__version__ = "0.1.0"
