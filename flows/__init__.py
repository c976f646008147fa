"""Prefect flows composing the tasks, and the ``react3d`` command line."""
