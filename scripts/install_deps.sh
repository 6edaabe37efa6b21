#!/usr/bin/env bash
# Installs every build, run and test dependency from Debian 12's own packages.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES=(
  build-essential cmake
  catkin ros-core-dev rosbash python3-rostest python3-rosunit librostest-dev
  ros-message-generation ros-message-runtime python3-genpy python3-gencpp
  libroscpp-dev libroslib-dev libtf2-ros-dev librviz-dev rviz
  libstd-msgs-dev libgeometry-msgs-dev libsensor-msgs-dev libvisualization-msgs-dev
  libnav-msgs-dev libtrajectory-msgs-dev python3-nav-msgs python3-trajectory-msgs
  ros-robot-state-publisher libstd-srvs-dev python3-std-srvs ros-std-srvs
  libactionlib-dev python3-actionlib libactionlib-msgs-dev python3-actionlib-msgs libinteractive-markers-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure python3-matplotlib python3-numpy python3-yaml
  xvfb x11-apps imagemagick libgl1-mesa-dri xauth python3-pil
  python3-rospy python3-std-msgs python3-geometry-msgs python3-sensor-msgs python3-visualization-msgs
  liburdfdom-dev liburdfdom-tools liboctomap-dev octomap-tools
  libeigen3-dev libboost-dev libyaml-cpp-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev libfcl-dev
  libopenvdb-dev libassimp-dev
  clang libclang-rt-14-dev
  libopenmpi-dev openmpi-bin
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} Debian packages already installed"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends "${missing[@]}"
