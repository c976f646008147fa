"""Pickle-free serialization of stage results: JSON structure + numpy arrays in one compressed npz.

Stage outputs are pydantic models and dataclasses from ``react3d_core`` holding numpy arrays
(masks, face ids, meshes). They are encoded as a JSON tree whose leaves reference arrays stored
beside it; classes are rebuilt only from ``react3d_core`` modules, so loading a file never runs
foreign code (unlike a pickle on shared storage).
"""

from __future__ import annotations

import dataclasses
import importlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import BaseModel

from react3d_core.npyio import load_npz

ALLOWED_PREFIX = "react3d_core."


class _Encoder:
    def __init__(self) -> None:
        self.arrays: dict[str, np.ndarray] = {}

    def _array(self, a: np.ndarray) -> dict[str, Any]:
        key = f"a{len(self.arrays)}"
        if a.dtype == bool:  # masks: 8x smaller packed
            self.arrays[key] = np.packbits(a.ravel())
            return {"__bits__": key, "shape": list(a.shape)}
        self.arrays[key] = a
        return {"__nd__": key}

    def enc(self, x: Any) -> Any:  # noqa: PLR0911 - one branch per supported kind
        if x is None or isinstance(x, (bool, int, float, str)):
            return x
        if isinstance(x, np.ndarray):
            return self._array(x)
        if isinstance(x, np.generic):
            return x.item()
        if isinstance(x, Path):
            return {"__path__": str(x)}
        if isinstance(x, tuple):
            return {"__tuple__": [self.enc(v) for v in x]}
        if isinstance(x, list):
            return [self.enc(v) for v in x]
        if isinstance(x, dict):
            return {"__dict__": [[self.enc(k), self.enc(v)] for k, v in x.items()]}
        if isinstance(x, BaseModel):
            return {"__model__": _qualname(x), "fields": {k: self.enc(getattr(x, k)) for k in type(x).model_fields}}
        if dataclasses.is_dataclass(x) and not isinstance(x, type):
            return {"__dc__": _qualname(x),
                    "fields": {f.name: self.enc(getattr(x, f.name)) for f in dataclasses.fields(x) if f.init}}
        raise TypeError(f"cannot serialize {type(x).__name__}")


def _qualname(x: Any) -> str:
    cls = type(x)
    if not cls.__module__.startswith(ALLOWED_PREFIX):
        raise TypeError(f"only react3d_core classes are serialized, not {cls.__module__}.{cls.__qualname__}")
    return f"{cls.__module__}:{cls.__qualname__}"


def _class(name: str) -> type:
    mod, _, qual = name.partition(":")
    if not mod.startswith(ALLOWED_PREFIX):
        raise ValueError(f"refusing to load class from {mod}")
    obj: Any = importlib.import_module(mod)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def _dec(x: Any, arrays: Any) -> Any:
    if isinstance(x, list):
        return [_dec(v, arrays) for v in x]
    if not isinstance(x, dict):
        return x
    if "__nd__" in x:
        return arrays[x["__nd__"]]
    if "__bits__" in x:
        shape = tuple(x["shape"])
        return np.unpackbits(arrays[x["__bits__"]], count=int(np.prod(shape))).astype(bool).reshape(shape)
    if "__path__" in x:
        return Path(x["__path__"])
    if "__tuple__" in x:
        return tuple(_dec(v, arrays) for v in x["__tuple__"])
    if "__dict__" in x:
        return {_dec(k, arrays): _dec(v, arrays) for k, v in x["__dict__"]}
    if "__model__" in x:
        return _class(x["__model__"])(**{k: _dec(v, arrays) for k, v in x["fields"].items()})
    if "__dc__" in x:
        return _class(x["__dc__"])(**{k: _dec(v, arrays) for k, v in x["fields"].items()})
    raise ValueError(f"unknown node {sorted(x)}")


def dumps(obj: Any) -> bytes:
    """Encode ``obj`` to npz bytes."""
    e = _Encoder()
    tree = json.dumps(e.enc(obj))
    buf = io.BytesIO()
    np.savez_compressed(buf, __tree__=np.frombuffer(tree.encode(), dtype=np.uint8), **e.arrays)
    return buf.getvalue()


def loads(data: bytes) -> Any:
    """Decode bytes written by :func:`dumps` (pickles refused)."""
    return loads_sized(data)[0]


def loads_sized(data: bytes) -> tuple[Any, int]:
    """:func:`loads`, and roughly how many bytes the decoded arrays take (packed masks count unpacked):
    what keeping the object in memory costs."""
    arrays = load_npz(data)
    tree_bytes = arrays.pop("__tree__").tobytes()
    tree = json.loads(tree_bytes.decode())
    packed = set(_bit_keys(tree))
    size = len(tree_bytes) + sum(a.nbytes * (8 if k in packed else 1) for k, a in arrays.items())
    return _dec(tree, arrays), size


def _bit_keys(x: Any) -> Any:
    """Keys of the bit-packed arrays in an encoded tree."""
    if isinstance(x, list):
        for v in x:
            yield from _bit_keys(v)
    elif isinstance(x, dict):
        if "__bits__" in x:
            yield x["__bits__"]
        for v in x.values():
            yield from _bit_keys(v)
