#!/usr/bin/env bash
# README command 2: build the package and its tests, run every gtest and rostest through
# catkin, then the unit tests again under ASan+UBSan and every fuzz target for FUZZ_SECONDS
# (scripts/run_sanitized.sh); exit non-zero on any failure or error.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
if ! command -v catkin_make >/dev/null; then
  echo "run_tests: catkin_make not found; run scripts/install_deps.sh (or command 1 of README.md) first" >&2
  exit 1
fi
mow_build
mow_build tests
# One test at a time: the rviz test renders on the CPU (Mesa llvmpipe) and, beside a test
# that computes on both cores, lags by many seconds.
mow_build run_tests -j1
mow_source_ws
# catkin_make run_tests exits 0 even when tests fail; catkin_test_results does not.
catkin_test_results --verbose "${WS}/build/test_results"
"${REPO}/scripts/run_sanitized.sh"
