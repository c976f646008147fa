#!/usr/bin/env bash
# Installs everything REACT3D needs on a fresh Debian/Ubuntu machine with Python 3.11 (idempotent: it
# checks the system libraries, the Python packages and the npm tool first and installs only what is
# missing, so a second call takes about a second).
# Usage: bash scripts/setup.sh [extras]   e.g. bash scripts/setup.sh test
set -euo pipefail
cd "$(dirname "$0")/.."
extras="${1:-}"
SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
need_apt=""
for lib in libusb-1.0.so.0 libgomp.so.1; do
  ldconfig -p 2>/dev/null | grep -q "$lib" || need_apt=1
done
if [ -n "$need_apt" ] && command -v apt-get >/dev/null; then
  echo "[setup] installing system libraries (libusb-1.0-0, libgomp1) ..."
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libusb-1.0-0 libgomp1 >/dev/null
fi
PY="${PYTHON:-python3}"
"$PY" -c 'import sys; assert sys.version_info[:2] == (3, 11), f"REACT3D needs Python 3.11, found {sys.version.split()[0]}"'
spec="."
[ -n "$extras" ] && spec=".[${extras}]"
if "$PY" scripts/installed.py "$extras"; then
  echo "[setup] Python packages for '${spec}': all installed"
else
  echo "[setup] pip install -e '${spec}' (CPU torch) ..."
  "$PY" -m pip install -q --disable-pip-version-check -e "$spec"
fi
if [[ ",${extras}," == *",test,"* ]] && command -v npm >/dev/null; then
  # S3-compatible object store for the storage tests: s3rver, a Node server keeping objects on disk
  if [ ! -x .tools/s3rver/node_modules/.bin/s3rver ]; then
    echo "[setup] npm install s3rver@3.7.1 into .tools/s3rver ..."
    npm install --silent --no-audit --no-fund --prefix .tools/s3rver s3rver@3.7.1 >/dev/null || echo "[setup] s3rver unavailable: S3 tests will be skipped"
  fi
fi
