"""Constants the heuristic's modules share: array layouts, image conventions and statistics, not
thresholds (those are the config sections of ``perception.heuristic``)."""

import numpy as np

XYZ = 3  # coordinates of a point
RGB = 3  # channels of a colour image ...
COLOUR_NDIM = 3  # ... which is (rows, columns, channels)
REFERENCE_WIDTH_PX = 640.0  # shifts and blurs in pixels are stated for a 640 px wide image and scale with the width
MAD_SIGMA = 1.4826  # median absolute deviation -> standard deviation of a normal distribution
NEIGHBOURS = np.ones((3, 3), np.uint8)  # a pixel and its 8 neighbours (morphology kernel)
CONNECTIVITY = 8  # pixels touching at a corner are one region
MIN_KERNEL = 3  # smallest odd morphology / median kernel (px)
