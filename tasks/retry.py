"""Which failures are worth retrying: transient ones (GPU OOM, endpoint timeouts, lost connections).

Bad input (InputError, ConfigError) and bugs fail at once with their message.
"""

from __future__ import annotations

from typing import Any

TRANSIENT_NAMES = ("OutOfMemory", "Timeout", "ConnectionError", "ConnectionReset", "RemoteDisconnected",
                   "TransientError", "URLError", "HTTPError")


def is_transient(exc: BaseException) -> bool:
    from react3d_core.errors import ConfigError, InputError

    if isinstance(exc, (InputError, ConfigError)):
        return False
    if isinstance(exc, (TimeoutError, ConnectionError)):
        return True
    name = type(exc).__name__
    return any(n in name for n in TRANSIENT_NAMES) or "out of memory" in str(exc).lower()


def retry_transient(task: Any, task_run: Any, state: Any) -> bool:
    """Prefect ``retry_condition_fn``: retry only transient exceptions."""
    try:
        state.result()
    except Exception as exc:  # noqa: BLE001 - state.result() re-raises the task's exception
        return is_transient(exc)
    return False


class TransientError(RuntimeError):
    """Raise from a stage for a failure that a retry may fix (used by fault-injection tests too)."""
