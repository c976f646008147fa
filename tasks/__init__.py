"""Prefect tasks: thin wrappers over react3d_core stages with content cache keys and store handles."""
