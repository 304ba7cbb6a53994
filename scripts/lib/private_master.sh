# Sourced by the scripts that run the nodelets (ros_demo.sh, soak.sh): a roscore of their
# own on a free port, so that runs never collide with another master on the machine.
#
#   start_private_master LOG_DIR     exports ROS_MASTER_URI and ROS_LOG_DIR, sets core_pid,
#                                    writes LOG_DIR/roscore.log; returns 1 if it did not start
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
