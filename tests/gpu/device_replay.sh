#!/usr/bin/env bash
# The GPU checks of the bundled scenes on a lent device machine, which has a CUDA device but none of the
# pipeline's libraries (Qt, OpenImageIO, Assimp...), so tst_gpu cannot run there (docs/TESTING.md "GPU tests").
#   tests/gpu/device_replay.sh prepare [BUILD_DIR]   here: builds gpu_replay and tst_gpu, writes the bundled
#       scenes' prepared frames with their CPU films (tst_gpu bundledScenesMatchCpu, SYLVA_GPU_REPLAY_DIR),
#       checks the replay on the CPU (gpu_replay --cpu: the same bits) and packs the frames, gpu_replay and
#       libtbb into build/gpu_replay.tar.xz (about 40 MB: under the device tool's 64 MiB carry)
#   tests/gpu/device_replay.sh run                  on the device machine (device tool: carry
#       ["build/gpu_replay.tar.xz"]): unpacks it and traces every frame on the GPU against its CPU film
# Ends with gpu_replay's name=value lines; exit 1 when a frame is off.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
PACK="$ROOT/build/gpu_replay.tar.xz"
case "${1:-}" in
  prepare)
    B="${2:-$ROOT/build/release}"
    cmake --build "$B" -j 2 --target gpu_replay tst_gpu >/dev/null
    STAGE="$ROOT/build/gpu_replay"
    rm -rf "$STAGE" && mkdir -p "$STAGE/frames" "$STAGE/lib"
    SYLVA_GPU_REPLAY_DIR="$STAGE/frames" QT_QPA_PLATFORM=offscreen "$B/tests/gpu/tst_gpu" bundledScenesMatchCpu >/dev/null
    "$B/tests/gpu/gpu_replay" "$STAGE/frames" --cpu | tail -2
    cp "$B/tests/gpu/gpu_replay" "$STAGE/"
    cp -L "$(ldd "$B/tests/gpu/gpu_replay" | awk '/libtbb/ {print $3}')" "$STAGE/lib/"
    tar -C "$ROOT/build" -cf - gpu_replay | xz -6 -T2 > "$PACK"
    ls -la "$PACK"
    ;;
  run)
    [[ -f "$PACK" ]] || { echo "no $PACK: run '$0 prepare' on the build machine and carry it" >&2; exit 1; }
    WORK="$(mktemp -d)"
    trap 'rm -rf "$WORK"' EXIT
    # python3's tarfile reads .tar.xz wherever xz itself is missing
    python3 -c "import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" "$PACK" "$WORK"
    nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || true
    LD_LIBRARY_PATH="$WORK/gpu_replay/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$WORK/gpu_replay/gpu_replay" "$WORK/gpu_replay/frames"
    ;;
  *)
    sed -n '2,10p' "$0"
    exit 2
    ;;
esac
