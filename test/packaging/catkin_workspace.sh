#!/usr/bin/env bash
# alvio as a package in a user's own catkin workspace: catkin_make configures it and
# generates its messages, and the devel space finds the package, its nodelet plugins and
# its launch files. A python3 without Debian's ROS modules comes first on PATH, as with
# pyenv or conda; the README's -DPYTHON_EXECUTABLE=/usr/bin/python3 must be enough.
#
#   test/packaging/catkin_workspace.sh SOURCE_DIR LOG_DIR
#
# The workspace lives in a temporary folder outside the source tree and is removed at the
# end: its src/alvio links back to the source, and inside the tree (as under build/) that
# link made roslaunch find every launch file many times, so `./alvio demo` failed after the
# tests.
set -euo pipefail
src="$(cd "$1" && pwd)"
logs="$2"
rm -rf "$logs"
mkdir -p "$logs"
ws="$(mktemp -d "${TMPDIR:-/tmp}/alvio_catkin_ws.XXXXXX")"
trap 'cp -f "$ws/catkin_make.log" "$logs/" 2>/dev/null; rm -rf "$ws"' EXIT
mkdir -p "$ws/src" "$ws/fake-bin"
ln -s "$src" "$ws/src/alvio"

# A python3 that sees no dist-packages (-S: no site): what a pyenv python3 looks like to ROS.
cat >"$ws/fake-bin/python3" <<'PY'
#!/bin/sh
exec /usr/bin/python3 -S "$@"
PY
chmod +x "$ws/fake-bin/python3"
if "$ws/fake-bin/python3" -c 'import ament_package' 2>/dev/null; then
  echo "catkin_workspace: the fake python3 still imports ament_package" >&2
  exit 1
fi

cd "$ws"
export PATH="$ws/fake-bin:$PATH"
unset PYTHONPATH AMENT_PREFIX_PATH CMAKE_PREFIX_PATH ROS_PACKAGE_PATH || true
# Configure and build only the generated messages: the configure step is where workspace
# builds break (the full build is the same CMakeLists as ./alvio build's).
if ! catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=OFF \
  alvio_generate_messages_cpp >"$ws/catkin_make.log" 2>&1; then
  tail -30 "$ws/catkin_make.log" >&2
  echo "catkin_workspace: catkin_make failed (log: $logs/catkin_make.log)" >&2
  exit 1
fi
[[ -f devel/include/alvio/PipelineStatus.h ]] || { echo "no generated PipelineStatus.h" >&2; exit 1; }

set +u
# shellcheck disable=SC1091
source devel/setup.bash
set -u
found="$(rospack find alvio)"
[[ "$found" == "$ws/src/alvio" ]] || { echo "rospack find alvio: '$found'" >&2; exit 1; }
rospack plugins --attrib=plugin nodelet | grep -q "^alvio " ||
  { echo "alvio's nodelet plugins are not exported" >&2; exit 1; }
[[ -f "$(rospack find alvio)/launch/alvio.launch" ]] ||
  { echo "launch/alvio.launch not found through rospack" >&2; exit 1; }
# roslaunch looks a launch file up by walking the whole package folder: one hit, or it stops.
hits="$(/usr/bin/python3 -c \
  'import roslib.packages as p; print(len(p.find_resource("alvio", "sim.launch")))')"
[[ "$hits" == 1 ]] || { echo "roslaunch would find sim.launch $hits times in alvio" >&2; exit 1; }
echo "catkin_workspace: configured, messages generated, package and nodelet plugins found"
