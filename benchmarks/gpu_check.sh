#!/usr/bin/env bash
# The GPU checks in one go: gpu-marked tests, model throughput, the mask copy, the 300-frame scene
# (with packed and with plain mask copies), the stage's profile.
#   bash benchmarks/gpu_check.sh OUTDIR        # on a machine with a CUDA GPU and the project installed
# Wheels in .whl/ (if any) are installed into /tmp/site first: for a machine without a registry.
set -o pipefail
OUT_DIR=${1:-benchmarks/results/gpu}
mkdir -p "$OUT_DIR"
if ls .whl/*.whl >/dev/null 2>&1; then
  SITE=$(mktemp -d /tmp/react3d-gpu-site.XXXXXX)  # our own folder: nothing of the machine's is touched
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target "$SITE" .whl/*.whl || exit 1
  export PYTHONPATH=$SITE:$PWD
  if ! python3 -c "import transformers" 2>"$OUT_DIR/carried_transformers.err"; then  # keep the machine's own
    rm -rf "$SITE"/transformers "$SITE"/transformers-*.dist-info
  fi
fi
export PYTHONUNBUFFERED=1 HF_HUB_OFFLINE=1
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv | tee "$OUT_DIR/nvidia_smi.txt"
python3 -c "import torch, transformers, sys; print(sys.version.split()[0], torch.__version__, transformers.__version__, torch.cuda.get_device_name(0))" | tee -a "$OUT_DIR/nvidia_smi.txt"
timeout 120 python3 -m pytest -q -p no:cacheprovider -m gpu tests/perception/models/test_models_gpu.py tests/perception/models/test_models_host_sync.py 2>&1 | tee "$OUT_DIR/gpu_tests.log"
timeout 120 python3 benchmarks/bench_models.py --images 16 --rebuild-calls 1 --json "$OUT_DIR/bench_models.json" 2>&1 | tee "$OUT_DIR/bench_models.log"
timeout 60 python3 benchmarks/bench_models.py --mask-transfer --models "" --json "$OUT_DIR/mask_transfer.json" 2>&1 | tee "$OUT_DIR/mask_transfer.log"
timeout 300 python3 benchmarks/bench_models_scene.py --json "$OUT_DIR/bench_models_scene.json" 2>&1 | tee "$OUT_DIR/bench_models_scene.log"
# the same scene with SAM's masks copied one byte per pixel (the 'before' of the bit-packing), same machine
timeout 150 python3 benchmarks/bench_models_scene.py --quick --plain-mask-copy --json "$OUT_DIR/bench_models_scene_plain_masks.json" 2>&1 | tee "$OUT_DIR/bench_models_scene_plain_masks.log"
timeout 120 python3 benchmarks/profile_models_stage.py --quick --out "$OUT_DIR/profile" 2>&1 | tee "$OUT_DIR/profile.log"
