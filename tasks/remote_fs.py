"""Calls to an object store that survive a store restart and fail with one line.

botocore and s3fs already repeat a failed request a few times, over ~6-10 s; a store that restarts, or a
network that drops for longer, still surfaces as ``EndpointConnectionError`` and a traceback in the middle
of a scene. :class:`ResilientFS` wraps the fsspec filesystem that :func:`tasks.storage.filesystem` hands
out and, for every public call:

- retries what a retry can fix (connection refused or reset, timeouts, the store's 5xx answers) with
  doubling waits, for up to ``REACT3D_STORE_RETRY_SECONDS`` (default 120), one warning line per retry; past
  that, :class:`StoreUnavailableError` (a ``ConnectionError``, so Prefect's retry condition and the
  dataset's table treat it as transient) names the store and the object;
- turns refused credentials into :class:`StoreAccessError`, one line, at once (retrying cannot help);
- turns a download that the local disk cannot hold (no space, quota, file size limit) into one
  :class:`~react3d_core.errors.InputError` naming the local folder and the object.

Every call the code makes is idempotent (whole-object puts and gets, listings, deletes), so repeating one
after a lost answer is safe; objects are only ever trusted after their size and hash are checked by the
caller (tasks/storage.py, tasks/scan_cache.py, tasks/store.py).
"""

from __future__ import annotations

import errno
import functools
import logging
import os
import time
from typing import Any

from react3d_core.errors import InputError

DEFAULT_RETRY_SECONDS = 120.0
FIRST_WAIT_S = 1.0
MAX_WAIT_S = 15.0

_log = logging.getLogger("react3d.store")

_DISK_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG}
_STORE_BUSY_ERRNOS = {errno.EBUSY, errno.EREMOTEIO, errno.ETIMEDOUT, errno.ECONNRESET, errno.ECONNREFUSED}
_DOWNLOADS = {"get", "get_file"}
_UPLOADS = {"put", "put_file"}


class StoreUnavailableError(ConnectionError):
    """The store did not answer within the retry budget (transient: a later attempt may succeed)."""


class StoreAccessError(InputError):
    """The store refused these credentials or this bucket (not transient)."""


def retry_seconds() -> float:
    """How long calls keep retrying an unreachable store (``REACT3D_STORE_RETRY_SECONDS``)."""
    raw = os.environ.get("REACT3D_STORE_RETRY_SECONDS", str(DEFAULT_RETRY_SECONDS))
    try:
        return max(0.0, float(raw))
    except ValueError:
        raise InputError(None, f"REACT3D_STORE_RETRY_SECONDS={raw!r} is not a number of seconds") from None


def is_store_transient(exc: BaseException) -> bool:
    """Whether ``exc`` says the store could not be reached or was busy (a retry can help)."""
    if isinstance(exc, StoreUnavailableError):
        return False  # already retried for the whole budget
    if isinstance(exc, (ConnectionError, TimeoutError)):
        return True
    try:
        import botocore.exceptions as be

        if isinstance(exc, (be.ConnectionError, be.HTTPClientError)):
            return True  # EndpointConnectionError, ConnectTimeoutError, ConnectionClosedError, ReadTimeoutError
    except ImportError:  # pragma: no cover - a store other than S3
        pass
    try:
        import aiohttp

        if isinstance(exc, (aiohttp.ClientConnectionError, aiohttp.ClientPayloadError)):
            return True
    except ImportError:  # pragma: no cover
        pass
    return isinstance(exc, OSError) and not isinstance(exc, (FileNotFoundError, PermissionError)) \
        and exc.errno in _STORE_BUSY_ERRNOS  # s3fs maps 500/503 answers to EREMOTEIO/EBUSY


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text.splitlines()[0][:200]}" if text else type(exc).__name__


def _remote_name(name: str, args: tuple[Any, ...], scheme: str = "s3") -> str:
    """The object a call is about, as ``s3://...`` (the first of a batch, with the batch size)."""
    first = args[1] if name in _UPLOADS and len(args) > 1 else (args[0] if args else "")
    if isinstance(first, dict):
        first = list(first)
    if isinstance(first, (list, tuple)):
        n = len(first)
        first = (first[0] if n else "") if n <= 1 else f"{first[0]} (and {n - 1} more)"
    s = str(first)
    return s if "://" in s else f"{scheme}://{s}"


def _local_dir(args: tuple[Any, ...], kwargs: dict[str, Any]) -> str:
    """The local folder a download writes into (for the disk-full line)."""
    target = kwargs.get("lpath", args[1] if len(args) > 1 else "")
    if isinstance(target, (list, tuple)):
        target = target[0] if target else ""
    parts = os.path.dirname(str(target)).split(os.sep)
    for i, part in enumerate(parts):  # name the folder, not the temporary a download is assembled in
        if part.startswith(".") and part.endswith(".tmp"):
            parts = parts[:i]
            break
    return os.sep.join(parts) or "."


class ResilientFS:
    """An fsspec filesystem whose public calls retry an unreachable store and fail with one line."""

    def __init__(self, fs: Any, endpoint: str) -> None:
        self._fs = fs
        self.endpoint = endpoint
        protocol = fs.protocol
        self.scheme = str(protocol[0] if isinstance(protocol, (tuple, list)) else protocol)

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._fs, name)
        if name.startswith("_") or not callable(attr):
            return attr

        @functools.wraps(attr)
        def call(*args: Any, **kwargs: Any) -> Any:
            return self._call(name, attr, args, kwargs)

        return call

    def _name(self, name: str, args: tuple[Any, ...]) -> str:
        return _remote_name(name, args, self.scheme)

    def _call(self, name: str, fn: Any, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
        budget = retry_seconds()
        t0 = time.monotonic()
        wait, tries = FIRST_WAIT_S, 0
        while True:
            tries += 1
            try:
                return fn(*args, **kwargs)
            except FileNotFoundError:
                raise
            except PermissionError as exc:
                if not _during_lost_connection(exc):
                    raise StoreAccessError(self._name(name, args), f"the store at {self.endpoint} refused access "
                                           f"({_first_line(exc)}); check AWS_ACCESS_KEY_ID / AWS_SECRET_ACCESS_KEY "
                                           "and the bucket's permissions") from exc
                last: BaseException = exc
            except OSError as exc:
                if name in _DOWNLOADS and exc.errno in _DISK_ERRNOS:
                    raise InputError(_local_dir(args, kwargs),
                                     f"cannot hold the download of {self._name(name, args)} ({exc.strerror}); free "
                                     "space on this disk, or set REACT3D_CACHE to a larger one") from None
                if not is_store_transient(exc):
                    raise
                last = exc
            except Exception as exc:  # noqa: BLE001 - botocore/aiohttp errors that are not OSErrors
                if not is_store_transient(exc):
                    raise
                last = exc
            self._wait_or_give_up(name, args, last, t0, tries, wait, budget)
            wait = min(wait * 2, MAX_WAIT_S)

    def _wait_or_give_up(self, name: str, args: tuple[Any, ...], last: BaseException, t0: float, tries: int,
                         wait: float, budget: float) -> None:
        """Sleep before the next try, or raise :class:`StoreUnavailableError` when the budget is spent."""
        elapsed = time.monotonic() - t0
        if elapsed + wait > budget:
            raise StoreUnavailableError(
                f"{self._name(name, args)}: the store at {self.endpoint} did not answer for {elapsed:.0f} s "
                f"({tries} tries of {name}; last: {_first_line(last)}); is it running? "
                "(AWS_ENDPOINT_URL; REACT3D_STORE_RETRY_SECONDS sets how long to wait)") from last
        _log.warning("react3d: the store at %s did not answer %s of %s (%s); try %d in %.0f s",
                     self.endpoint, name, self._name(name, args), _first_line(last), tries + 1, wait)
        time.sleep(wait)


def _during_lost_connection(exc: BaseException) -> bool:
    """Whether ``exc`` was raised while cleaning up after a lost connection (s3fs aborts a multipart
    upload whose part could not be sent; a server that cannot abort answers 405, seen as PermissionError):
    the lost connection is the failure to report and retry, not the refused clean-up."""
    seen = set()
    e: BaseException | None = exc.__cause__ or exc.__context__
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        if is_store_transient(e):
            return True
        e = e.__cause__ or e.__context__
    return False
