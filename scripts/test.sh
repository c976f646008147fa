#!/usr/bin/env bash
# One command: install (system libraries included), then run the fast test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh test
export TMPDIR="${TMPDIR:-/tmp}"
python3 -m pytest -n 2 --dist loadfile -q "$@"
