"""Quiet, robust defaults for an embedded Prefect run (set before ``import prefect``; user values win).

Measured on 2 cores (docs/orchestration.md): the temporary SQLite server needs > 20 s to start the
first time, prints telemetry errors on a closed network and noisy shutdown tracebacks.
"""

from __future__ import annotations

import os

DEFAULTS = {
    "PREFECT_SERVER_ANALYTICS_ENABLED": "false",
    "PREFECT_LOGGING_LEVEL": "WARNING",
    "PREFECT_SERVER_LOGGING_LEVEL": "CRITICAL",
    "PREFECT_LOGGING_LOG_PRINTS": "false",
    "PREFECT_SERVER_EPHEMERAL_STARTUP_TIMEOUT_SECONDS": "120",
    "PREFECT_RESULTS_PERSIST_BY_DEFAULT": "true",
    "PREFECT_LOGGING_TO_API_WHEN_MISSING_FLOW": "ignore",
}


def configure() -> None:
    """Apply the defaults that the user has not set."""
    for k, v in DEFAULTS.items():
        os.environ.setdefault(k, v)
