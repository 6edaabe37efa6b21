#!/usr/bin/env bash
# Installs every build, run and test dependency from Debian 12's own packages.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PACKAGES=(
  build-essential cmake
  catkin ros-core-dev rosbash python3-rostest python3-rosunit
  libroscpp-dev libtf2-ros-dev librviz-dev rviz
  liburdfdom-dev liburdfdom-tools liboctomap-dev octomap-tools
  libeigen3-dev libyaml-cpp-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev
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
