"""Quiet, robust defaults for an embedded Prefect run (set before ``import prefect``; user values win),
which server a command uses (:func:`check_server`), and the guard that makes Prefect decode only JSON
result records (:func:`guard_result_records`).

Measured on 2 cores (docs/orchestration.md): a SQLite server needs > 20 s to start the first time (a
fresh database is migrated), prints telemetry errors on a closed network and noisy shutdown tracebacks.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import sys
import threading
from typing import Any

DEFAULTS = {
    "PREFECT_SERVER_ANALYTICS_ENABLED": "false",
    "PREFECT_LOGGING_LEVEL": "WARNING",
    "PREFECT_SERVER_LOGGING_LEVEL": "CRITICAL",
    "PREFECT_LOGGING_LOG_PRINTS": "false",
    "PREFECT_SERVER_EPHEMERAL_STARTUP_TIMEOUT_SECONDS": "120",
    "PREFECT_RESULTS_PERSIST_BY_DEFAULT": "true",
    "PREFECT_LOGGING_TO_API_WHEN_MISSING_FLOW": "ignore",
    # records on shared storage are JSON, never pickles (and only JSON ones are read: see below)
    "PREFECT_RESULTS_DEFAULT_SERIALIZER": "json",
}


def configure() -> None:
    """Apply the defaults that the user has not set."""
    for k, v in DEFAULTS.items():
        os.environ.setdefault(k, v)
    from .storage import configure_result_storage

    configure_result_storage()  # result records beside the shared store (REACT3D_STORE)


# --- Which server a command talks to ----------------------------------------------------------------
#
# A server named by ``PREFECT_API_URL`` (environment or Prefect profile: ``react3d server``, ``prefect
# server start``, a shared one) is used as is. Without one, react3d commands share a local server that
# the first of them starts and that stops itself when unused (``flows.local_server``). Plain Python use
# of the flows without a URL gets Prefect's temporary server, started and stopped with the process.

TEMPORARY_NOTE = ("react3d: starting a temporary Prefect server for this process (~5-15 s); to reuse one across "
                  "runs start `react3d server` and set PREFECT_API_URL=http://127.0.0.1:4200/api")


def api_url() -> str | None:
    """The Prefect API this process will use (environment or active profile); None = none named."""
    configure()
    from prefect.settings import get_current_settings

    return get_current_settings().api.url or None


def server_reachable(url: str, timeout: float = 3.0) -> bool:
    """Whether a Prefect API answers ``GET <url>/health`` (plain urllib: no client set-up cost)."""
    import urllib.error
    import urllib.request

    try:
        with urllib.request.urlopen(url.rstrip("/") + "/health", timeout=timeout) as resp:  # noqa: S310 (user's own URL)
            return resp.status == 200
    except (urllib.error.URLError, OSError, ValueError):
        return False


def check_server() -> str:
    """Before a command runs flows: ``"running"`` when ``PREFECT_API_URL`` names a server that answers,
    ``"local"`` when none is named (the command then uses react3d's local server: ``flows.local_server``).

    A URL that does not answer is a one-line :class:`~react3d_core.errors.ConfigError` instead of
    Prefect's retries and traceback minutes later."""
    url = api_url()
    if not url:
        return "local"
    if not server_reachable(url):
        from react3d_core.errors import ConfigError

        raise ConfigError(f"PREFECT_API_URL={url} does not answer: start it (`react3d server`) or unset "
                          "PREFECT_API_URL to let react3d start its local server")
    return "running"


# --- Result records: read only what react3d itself writes -------------------------------------------
#
# A Prefect result record names its own serializer, and Prefect 3 decodes the record with whatever it
# names: a record rewritten to ``serializer: pickle`` (or to JSON with ``jsonlib: pickle``, or an
# ``object_decoder`` of the writer's choice) runs code in every worker that reads the shared storage.
# ``guard_result_records`` checks the raw bytes of every record *before* Prefect decodes them: only the
# stock JSON serializer is allowed, and its payload may name no class outside modules already imported
# from trusted packages. A refused record reads as "not cached" (the task recomputes and overwrites it)
# or, when Prefect reads it as an upstream result, as a clear error.

TRUSTED_SERIALIZER: dict[str, Any] = {
    "type": "json",
    "jsonlib": "json",
    "object_encoder": "prefect.serializers.prefect_json_object_encoder",
    "object_decoder": "prefect.serializers.prefect_json_object_decoder",
    "dumps_kwargs": {},
    "loads_kwargs": {},
}
"""The only serializer configuration a record may name (Prefect's default JSON serializer, field by field)."""

TRUSTED_CLASS_MODULES = ("builtins", "pathlib", "datetime", "uuid", "react3d_core", "tasks", "flows", "prefect")
"""Packages whose classes a JSON payload may name (``__class__`` / ``__exc_type__``), if already imported."""

_log = logging.getLogger("react3d.cache")
_reported: set[str] = set()
_guard_lock = threading.Lock()


class UntrustedRecordError(ValueError):
    """A Prefect result record that react3d refuses to decode (foreign serializer or class)."""


def check_record_bytes(data: bytes | str) -> Any:
    """Validate a serialized ``ResultRecord`` without decoding its payload; returns the plain payload.

    Raises :class:`UntrustedRecordError` for anything but a current-format record with the trusted
    JSON serializer and a payload that names only trusted, already-imported classes."""
    try:
        record = json.loads(data)
    except (ValueError, UnicodeDecodeError) as exc:
        raise UntrustedRecordError(f"not a JSON result record ({exc.__class__.__name__})") from None
    if not isinstance(record, dict) or not isinstance(record.get("metadata"), dict) or not isinstance(record.get("result"), str):
        raise UntrustedRecordError("not a current-format result record (metadata + JSON result expected)")
    check_metadata(record["metadata"])
    return check_payload(record["result"])


def check_metadata(meta: Any) -> None:
    """Refuse record metadata whose serializer is not exactly :data:`TRUSTED_SERIALIZER`."""
    if isinstance(meta, (bytes, str)):
        try:
            meta = json.loads(meta)
        except (ValueError, UnicodeDecodeError):
            raise UntrustedRecordError("unreadable result record metadata") from None
    ser = meta.get("serializer") if isinstance(meta, dict) else None
    if ser != TRUSTED_SERIALIZER:
        kind = ser.get("type") if isinstance(ser, dict) else ser
        raise UntrustedRecordError(f"serializer {kind!r} with settings {ser!r} is not allowed "
                                   "(react3d reads only records written with Prefect's JSON serializer)")


def check_payload(text: bytes | str) -> Any:
    """Parse a JSON payload with the standard library (no hooks) and refuse untrusted class names."""
    try:
        payload = json.loads(text)
    except (ValueError, UnicodeDecodeError):
        raise UntrustedRecordError("result payload is not JSON") from None
    stack = [payload]
    while stack:
        x = stack.pop()
        if isinstance(x, list):
            stack.extend(x)
        elif isinstance(x, dict):
            for tag in ("__class__", "__exc_type__"):
                if tag in x and not _trusted_class_name(x[tag]):
                    raise UntrustedRecordError(f"payload names class {x[tag]!r}, outside the trusted, loaded modules")
            stack.extend(x.values())
    return payload


def _trusted_class_name(name: Any) -> bool:
    if not isinstance(name, str):
        return False
    module = name.rpartition(".")[0]
    # already imported: resolving the name imports nothing (no import-time side effects)
    return module.split(".")[0] in TRUSTED_CLASS_MODULES and module in sys.modules


def _refuse(data: bytes | str, exc: Exception) -> None:
    digest = hashlib.sha256(data if isinstance(data, bytes) else data.encode()).hexdigest()
    if digest not in _reported:
        _reported.add(digest)
        _log.warning("react3d: ignored a cached Prefect result record: %s; recomputing", exc)


def guard_result_records() -> None:
    """Make Prefect check every result record with :func:`check_record_bytes` before decoding it.

    Idempotent; called by every cached task definition (``tasks.keys.content_key``). Objects that a
    valid record points at are verified too (``tasks.store.verify_handles``): a record of a corrupt or
    missing object is treated as no record, so the task recomputes."""
    from prefect._internal.result_records import ResultRecord

    with _guard_lock:
        if getattr(ResultRecord, "_react3d_guarded", False):
            return
        orig_deserialize = ResultRecord.deserialize.__func__  # type: ignore[attr-defined]
        orig_split = ResultRecord.deserialize_from_result_and_metadata.__func__  # type: ignore[attr-defined]

        def deserialize(cls: type, data: bytes, backup_serializer: Any = None) -> Any:
            from .store import CorruptObjectError, verify_handles

            try:
                verify_handles(check_record_bytes(data))
            except UntrustedRecordError as exc:
                _refuse(data, exc)
                raise
            except CorruptObjectError:  # the store already said so in one line (quarantine)
                raise
            # never fall back to a serializer for bytes that are not a record
            return orig_deserialize(cls, data, backup_serializer=None)

        def deserialize_from_result_and_metadata(cls: type, result: bytes, metadata: bytes) -> Any:
            from .store import verify_handles

            try:
                check_metadata(metadata)
                verify_handles(check_payload(result))
            except UntrustedRecordError as exc:
                _refuse(metadata + result, exc)
                raise
            return orig_split(cls, result, metadata)

        ResultRecord.deserialize = classmethod(deserialize)  # type: ignore[assignment, method-assign]
        ResultRecord.deserialize_from_result_and_metadata = classmethod(deserialize_from_result_and_metadata)  # type: ignore[assignment, method-assign]
        ResultRecord._react3d_guarded = True  # type: ignore[attr-defined]

