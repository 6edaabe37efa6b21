#!/usr/bin/env bash
# rviz on a private Xvfb screen, for tests and machines without a display:
#   rviz_headless.sh DISPLAY_FILE [rviz arguments...]
# Xvfb picks a free display itself (-displayfd), so parallel runs do not collide; its name
# (":N") is written to DISPLAY_FILE for whoever takes screenshots, and rviz's process id to
# DISPLAY_FILE.pid for whoever measures its memory. Both processes end together.
set -euo pipefail
display_file=${1:?usage: rviz_headless.sh DISPLAY_FILE [rviz arguments...]}
shift
geometry=${MOW_XVFB_SCREEN:-1280x800x24}

number_file=$(mktemp)
Xvfb -displayfd 3 -screen 0 "${geometry}" -nolisten tcp 3>"${number_file}" &
xvfb=$!
rviz_pid=
stop() {
  [ -n "${rviz_pid}" ] && kill "${rviz_pid}" 2>/dev/null || true
  kill "${xvfb}" 2>/dev/null || true
  rm -f "${number_file}" "${display_file}.pid"
}
trap stop EXIT
trap 'exit 0' INT TERM

for _ in $(seq 100); do
  [ -s "${number_file}" ] && break
  kill -0 "${xvfb}" 2>/dev/null || { echo "rviz_headless: Xvfb failed to start" >&2; exit 1; }
  sleep 0.1
done
[ -s "${number_file}" ] || { echo "rviz_headless: Xvfb gave no display within 10 s" >&2; exit 1; }
export DISPLAY=":$(tr -d '[:space:]' <"${number_file}")"
echo "rviz_headless: Xvfb on ${DISPLAY} (${geometry})"
echo "${DISPLAY}" >"${display_file}.tmp" && mv "${display_file}.tmp" "${display_file}"

rviz "$@" &
rviz_pid=$!
echo "${rviz_pid}" >"${display_file}.pid.tmp" && mv "${display_file}.pid.tmp" "${display_file}.pid"
wait "${rviz_pid}"
