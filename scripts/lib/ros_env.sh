# Sourced by the scripts that run the nodelets (ros_demo.sh, soak.sh): the build's ROS
# environment, and a roscore of their own on a free port, so that runs never collide with
# another master on the machine. Both expect a `die` function.
#
#   source_ros_build BUILD           Debian's python and the build's devel space
#   start_private_master LOG_DIR     exports ROS_MASTER_URI and ROS_LOG_DIR, sets core_pid,
#                                    writes LOG_DIR/roscore.log; returns 1 if it did not start
source_ros_build() {
  # A pyenv python first on PATH breaks Debian's ROS.
  export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
  unset AMENT_PREFIX_PATH PYTHONPATH || true
  [[ -f $1/devel/setup.bash ]] || die "not built: run ./alvio build (or set ALVIO_BUILD_DIR)"
  set +u
  # shellcheck disable=SC1091
  source "$1/devel/setup.bash"
  set -u
}

start_private_master() {
  local dir="$1" port
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI="http://localhost:$port"
  export ROS_LOG_DIR="$dir/ros_log"
  roscore -p "$port" >"$dir/roscore.log" 2>&1 &
  core_pid=$!
  for _ in $(seq 100); do
    rosparam get /rosdistro >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  return 1
}
