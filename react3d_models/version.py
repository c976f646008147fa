"""Version of the model backend, in a module that imports nothing (so cache keys can name it without
importing torch, and workers with and without torch agree on heuristic/oracle keys)."""

# 2: at most max_detections boxes per frame; 3: settings from perception.models, package react3d_models
STAGE_VERSION = "3"
