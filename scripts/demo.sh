#!/usr/bin/env bash
# One command: install, then run the whole pipeline on the built-in demo scene with the default,
# weight-free settings and an embedded Prefect (no server to start). Output in ./demo_out.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh sim
export PREFECT_HOME="${PREFECT_HOME:-$PWD/.prefect-demo}"
react3d demo --out "${1:-demo_out}"
