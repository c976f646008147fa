"""``react3d bench``: the runner (set files, one isolated conversion per scene, evaluation), the scene
sets it ships (``sets/*.json``, package data) and the miss-cause tracer. The scripts in ``benchmarks/``
build on the same runner."""
