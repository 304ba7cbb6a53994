#!/usr/bin/env bash
# Build the libFuzzer targets of test/fuzz/ with clang (ASan + UBSan) into build-fuzz/
# and run each for N seconds from its seed corpus (test/fuzz/corpus/<target>/).
#
#   scripts/fuzz.sh [--seconds N] [target...]     default: 120 s each, every target
#
# Needs the normal build (./alvio build, run when missing): fuzz_config links the rest of
# libalvio_core from it. The growing corpus is kept in build-fuzz/corpus/<target>/, crash inputs in
# build-fuzz/artifacts/<target>/. Exit status 1 when a target crashed.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ALVIO_BUILD_DIR:-$ROOT/build}"
FUZZ_BUILD="${ALVIO_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
JOBS="${ALVIO_JOBS:-2}"
SECONDS_EACH=120
TARGETS=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) SECONDS_EACH="$2"; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) TARGETS+=("$1"); shift ;;
  esac
done
[[ ${#TARGETS[@]} -gt 0 ]] || TARGETS=(fuzz_config fuzz_euroc_csv fuzz_tum_trajectory fuzz_feature_msg)
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
log() { printf '\033[1m[fuzz]\033[0m %s\n' "$*" >&2; }

# clang is only needed here, not by the normal build: install it on demand.
if ! command -v clang++ >/dev/null; then
  log "installing clang"
  as_root() { if [[ $(id -u) -eq 0 ]]; then "$@"; else sudo "$@"; fi; }
  export DEBIAN_FRONTEND=noninteractive
  as_root apt-get update -qq
  as_root apt-get install -y -qq --no-install-recommends clang </dev/null
fi

# fuzz_config links the normal build's libalvio_core, fuzz_feature_msg its message headers.
if [[ ! -f $BUILD/devel/lib/libalvio_core.so || ! -d $BUILD/devel/include/alvio ]]; then
  ALVIO_BUILD_DIR="$BUILD" ALVIO_JOBS="$JOBS" "$ROOT/alvio" build
fi
if [[ ! -f $FUZZ_BUILD/CMakeCache.txt ]]; then
  log "configuring into $FUZZ_BUILD"
  cmake -S "$ROOT/test/fuzz" -B "$FUZZ_BUILD" -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=None -DALVIO_MAIN_BUILD="$BUILD" >/dev/null
fi
log "building (-j$JOBS)"
cmake --build "$FUZZ_BUILD" -j "$JOBS" --target "${TARGETS[@]}" >/dev/null

# Stop at the first crash, leak or UBSan report; huge single allocations count as bugs.
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
printf '%-22s %8s %12s %8s %s\n' target seconds executions corpus result
for t in "${TARGETS[@]}"; do
  corpus="$FUZZ_BUILD/corpus/$t" artifacts="$FUZZ_BUILD/artifacts/$t"
  mkdir -p "$corpus" "$artifacts"
  cp -n "$ROOT/test/fuzz/corpus/$t/"* "$corpus/" 2>/dev/null || true
  out="$FUZZ_BUILD/$t.log"
  if "$FUZZ_BUILD/$t" -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 -max_len=8192 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/" "$corpus" >"$out" 2>&1; then
    result=ok
  else
    result="CRASH (see $out and $artifacts)"
    status=1
  fi
  runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$out" | grep -oE '[0-9]+$' || echo ?)
  secs=$(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "$out" | grep -oE 'in [0-9]+' | grep -oE '[0-9]+' || echo ?)
  printf '%-22s %8s %12s %8s %s\n' "$t" "$secs" "$runs" "$(ls "$corpus" | wc -l)" "$result"
done
exit $status
