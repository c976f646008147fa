#!/usr/bin/env bash
# One command: install (system libraries and headless Chromium included), then run the fast test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh test
if ! command -v chromium >/dev/null && command -v apt-get >/dev/null; then
  echo "[test] installing Debian chromium for the viewer tests ..."
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq || true
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null || echo "[test] chromium unavailable: browser tests will be skipped"
fi
if ! command -v docker-compose >/dev/null && ! docker compose version >/dev/null 2>&1 && command -v apt-get >/dev/null; then
  echo "[test] installing docker-compose (validates docker-compose.yml; no engine needed) ..."
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq docker-compose >/dev/null 2>&1 || echo "[test] docker-compose unavailable: compose validation skipped"
fi
export TMPDIR="${TMPDIR:-/tmp}"
python3 -m pytest -n 2 --dist loadfile -q "$@"
