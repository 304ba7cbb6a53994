#!/usr/bin/env bash
# Copy the built programs and libraries into a folder of their own, so that long benchmark
# runs are not broken by a rebuild of build/ underneath them (a relinked program with the
# old library, or the reverse). Prints the frozen alvio_run; run it with
# LD_LIBRARY_PATH=<folder>/lib (LD_LIBRARY_PATH comes before the build's RUNPATH).
#
#   scripts/freeze_build.sh OUT_DIR        (scripts/bench.py --freeze does it for you)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ALVIO_BUILD_DIR:-$ROOT/build}"
out="${1:?usage: freeze_build.sh OUT_DIR}"
mkdir -p "$out/lib" "$out/bin"
cp -a "$BUILD"/devel/lib/*.so* "$out/lib/"
cp -a "$BUILD"/devel/lib/alvio/alvio_run "$BUILD"/devel/lib/alvio/alvio_sim "$out/bin/"
echo "$out/bin/alvio_run"
