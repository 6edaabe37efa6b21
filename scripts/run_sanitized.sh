#!/usr/bin/env bash
# The core library, the mow tool and their unit tests built with clang under
# AddressSanitizer and UndefinedBehaviorSanitizer; every unit test and every libFuzzer
# target (for FUZZ_SECONDS, default 30, from its seed corpus test/fuzz/corpus/<name>/) run,
# one job per core.
# Any failure, sanitizer report or fuzzer crash exits non-zero; a crashing input is kept in
# ${BUILD}/fuzz_artifacts/. Part of scripts/run_tests.sh (README command 2).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
BUILD=${MOW_SANITIZED_BUILD:-${REPO}/.sanitized_build}
FUZZ_SECONDS=${FUZZ_SECONDS:-30}
if ! command -v clang++ >/dev/null; then
  echo "run_sanitized: clang++ not found; run scripts/install_deps.sh first" >&2
  exit 1
fi
cmake -S "${REPO}/test/sanitized" -B "${BUILD}" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None >/dev/null
cmake --build "${BUILD}" -j"$(nproc)"

# halt_on_error: the first report fails the program, so it fails the run.
export ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:strict_string_checks=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# Cases that repeat what sanitized cases run at a coarser step or on another robot (the
# engine with a margin: test_margin; necks named for a plan: test_margin's Necks; the
# engine on robots with limits: test_certified_volumes and test_constraints; exact signs
# from 20 to 5 mm: test_engine_reference's delta-like robot at 10 mm; certified bounds from
# 10 to 5 mm: the tricylinder's and the limited robots'). Under the sanitizers the first two
# took about 9 of this stage's 33 minutes; on a slower day the last three about 6 of 41.
# scripts/run_tests.sh runs them all unsanitized.
SLOW_UNDER_SANITIZERS=EngineAgainstReference.DeltaLikeOverXyzAt5mmWithAMargin
SLOW_UNDER_SANITIZERS+=:Planning.AGoalNotJoinedAtTheClearanceNamesTheNeckAndTheClearanceThatPlans
SLOW_UNDER_SANITIZERS+=:EngineAgainstReference.RobotsWithLimitsAt10mm
SLOW_UNDER_SANITIZERS+=:Margin.ExactFiguresAgreeAt20And10And5mm
SLOW_UNDER_SANITIZERS+=:CertifiedVolumes.TheDeltaLikeRobotsFinerVolumesLieWithinTheCoarseBounds
mapfile -t SANITIZED_TESTS <"${BUILD}/unit_tests.txt"  # written by the CMake project
FAILED_LIST="${BUILD}/failed.txt"
: >"${FAILED_LIST}"

# One job's report is printed whole when it ends, so two jobs' lines never interleave.
run_unit_test() {
  local name=$1 start=${SECONDS} report
  if "${BUILD}/${name}" --gtest_brief=1 --gtest_filter="-${SLOW_UNDER_SANITIZERS}" >"${BUILD}/${name}.log" 2>&1; then
    echo "== ${name} (ASan+UBSan) passed in $((SECONDS - start)) s"
  else
    report=$(tail -n 30 "${BUILD}/${name}.log")
    printf '== %s (ASan+UBSan) FAILED in %s s; last lines of %s:\n%s\n' \
      "${name}" "$((SECONDS - start))" "${BUILD}/${name}.log" "${report}"
    echo "${name}" >>"${FAILED_LIST}"
  fi
}

run_fuzz_target() {
  local name=$1 report
  # A scratch copy: what the run adds to the corpus stays out of the source tree.
  local work="${BUILD}/fuzz_corpus/${name}"
  rm -rf "${work}" && mkdir -p "${work}" && cp "${REPO}/test/fuzz/corpus/${name}"/* "${work}/"
  if "${BUILD}/fuzz_${name}" -max_total_time="${FUZZ_SECONDS}" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="${BUILD}/fuzz_artifacts/${name}-" "${work}" >"${BUILD}/fuzz_${name}.log" 2>&1; then
    report=$(grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "${BUILD}/fuzz_${name}.log" | tr '\n' ' ')
    echo "== fuzz_${name}, ${FUZZ_SECONDS} s: ${report}; corpus $(ls "${work}" | wc -l) inputs"
  else
    report=$(tail -n 40 "${BUILD}/fuzz_${name}.log")
    printf '== fuzz_%s FAILED; last lines of %s:\n%s\n' "${name}" "${BUILD}/fuzz_${name}.log" "${report}"
    echo "fuzz_${name}" >>"${FAILED_LIST}"
  fi
}

# One job per core: most tests and every fuzzer run on one thread, and on 2 cores the stage
# took 33 to 41 of CI's 90 minutes one at a time. test_mow_cli runs alone afterwards:
# it times how fast mow stops on Ctrl-C, which a loaded machine would make flaky.
JOBS=$(nproc)
in_pool() {  # in_pool COMMAND ARG: start the job, first waiting while JOBS are running
  while [ "$(jobs -rp | wc -l)" -ge "${JOBS}" ]; do wait -n || true; done
  "$@" &
}
for name in "${SANITIZED_TESTS[@]}"; do
  [ "${name}" = test_mow_cli ] || in_pool run_unit_test "${name}"
done
mkdir -p "${BUILD}/fuzz_artifacts"
for corpus in "${REPO}"/test/fuzz/corpus/*/; do
  in_pool run_fuzz_target "$(basename "${corpus}")"
done
wait
run_unit_test test_mow_cli
mapfile -t failed <"${FAILED_LIST}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "run_sanitized: failed: ${failed[*]}" >&2
  exit 1
fi
echo "run_sanitized: ${#SANITIZED_TESTS[@]} unit tests and $(ls -d "${REPO}"/test/fuzz/corpus/*/ | wc -l) fuzz targets passed"
