#!/usr/bin/env bash
# Copy the built programs and libraries into a folder of their own, so that long benchmark
# runs are not broken by a rebuild of build/ underneath them (a relinked program with the
# old library, or the reverse). Prints the frozen alvio_run. The copies' RUNPATH points at
# each other (patchelf), so a frozen program run by hand loads the frozen libraries too.
#
#   scripts/freeze_build.sh OUT_DIR        (scripts/bench.py --freeze does it for you)
#
# Only programs and libraries are copied, not config/: a frozen program reads the --config it
# is given, and scripts/bench.py --bin FROZEN (without --freeze) passes the source tree's
# config/, which may have moved on since (an older build warns about keys it does not know and
# ignores them). scripts/bench.py --freeze also copies config/ into OUT_DIR/config and uses it.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ALVIO_BUILD_DIR:-$ROOT/build}"
out="${1:?usage: freeze_build.sh OUT_DIR}"
[[ -d "$BUILD/devel/lib" ]] || { echo "freeze_build.sh: no build in $BUILD (run ./alvio build)" >&2; exit 1; }

# A copy taken while make is relinking mixes old and new programs and libraries (a run that
# ignored --no-lines, then a crash), so refuse while a compiler or linker works in BUILD.
refuse_during_build() {
  local build_real cwd comm p
  build_real="$(cd "$BUILD" && pwd -P)"
  for p in /proc/[0-9]*; do
    cwd="$(readlink "$p/cwd" 2>/dev/null)" || continue
    case "$cwd/" in "$build_real"/*) ;; *) continue ;; esac
    comm="$(cat "$p/comm" 2>/dev/null)" || continue
    case "$comm" in
      make | gmake | ninja | cmake | cc1 | cc1plus | c++ | g++ | gcc | clang* | ld | ld.* | collect2 | ar | ranlib)
        echo "freeze_build.sh: a build is running in $BUILD (pid ${p#/proc/}, $comm);" \
          "wait for it to finish, then freeze again" >&2
        exit 1
        ;;
    esac
  done
}

refuse_during_build
programs=("$BUILD"/devel/lib/alvio/alvio_run "$BUILD"/devel/lib/alvio/alvio_sim)
# A program older than the core library was not relinked when the library last changed (only
# other targets were built since), so its idea of the library's types may be out of date: such
# a frozen alvio_sim crashed at start-up.
for program in "${programs[@]}"; do
  if [[ "$program" -ot "$BUILD/devel/lib/libalvio_core.so" ]]; then
    echo "freeze_build.sh: $program is older than libalvio_core.so" \
      "(not rebuilt since the library changed); build all targets (./alvio build), then" \
      "freeze again" >&2
    exit 1
  fi
done
mkdir -p "$out/lib" "$out/bin"
cp -a "$BUILD"/devel/lib/*.so* "$out/lib/"
cp -a "${programs[@]}" "$out/bin/"
# The build's RUNPATH names build/devel/lib: without this a frozen program run by hand loads
# the live libraries, whose types may have changed since (a crash in a destructor).
is_elf() { [[ "$(head -c 4 "$1" | od -An -c | tr -d ' ')" == '177ELF' ]]; }
for f in "$out"/bin/* "$out"/lib/*.so*; do
  [[ -f $f && ! -L $f ]] && is_elf "$f" || continue
  # shellcheck disable=SC2016
  case "$f" in "$out"/bin/*) rpath='$ORIGIN/../lib' ;; *) rpath='$ORIGIN' ;; esac
  patchelf --set-rpath "$rpath" "$f" ||
    { echo "freeze_build.sh: patchelf failed on $f (apt-get install patchelf)" >&2; exit 1; }
done
# A build that started during the copy may have replaced some of the files already copied.
refuse_during_build
echo "$out/bin/alvio_run"
