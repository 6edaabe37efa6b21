# Shared settings for the scripts in this folder; sourced, not run.
# Debian's /usr/bin/python3 has the ROS Python modules; a pyenv python3 earlier on PATH
# does not, and catkin then fails obscurely. Hence /usr/bin first and an explicit
# PYTHON_EXECUTABLE everywhere.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:${PATH}
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# The catkin workspace lives inside the clone (ignored by git) unless MOW_WS says otherwise.
WS=${MOW_WS:-${REPO}/.catkin_ws}
CATKIN_ARGS=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release)

mow_link_package() {
  # The package in the workspace is a folder of links to the clone's top-level entries, not
  # a link to the clone itself: that would contain the workspace and make a loop that
  # rosrun's and rospack's directory walks trip over.
  local package="${WS}/src/maximal_workspace"
  [ -L "${package}" ] && rm "${package}"
  mkdir -p "${package}"
  find "${package}" -mindepth 1 -maxdepth 1 -type l -delete
  local entry
  for entry in "${REPO}"/* "${REPO}"/.ci; do
    [ "${entry}" = "${WS}" ] || ln -s "${entry}" "${package}/"
  done
}

mow_build() {
  mow_link_package
  # catkin caches the test environment at the first configure, with only the folders that
  # exist then: without this one, PYTHONPATH lacks the generated messages and the Python
  # nodes of a rostest (demo_driver, test_rviz_demo) fail to import them on a clean clone.
  mkdir -p "${WS}/devel/lib/python3/dist-packages"
  (cd "${WS}" && catkin_make "${CATKIN_ARGS[@]}" -j"$(nproc)" "$@")
}

mow_source_ws() {
  # setup.bash reads unset variables; relax -u while it runs.
  set +u
  # shellcheck disable=SC1091
  source "${WS}/devel/setup.bash"
  set -u
}
