#!/usr/bin/env bash
# README command 1: install the dependencies, build the package, run the main job on the
# default robot: mow info, mow eval on the example poses, mow workspace at 10 mm (the
# maximal operational workspace, cached in ~/.ros/maximal_workspace), mow plan, and then the
# demo (launch/demo.launch): in rviz when there is a display (it runs until Ctrl-C), else
# headless, printing what it computed and where the files are, and stopping by itself.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
"${REPO}/scripts/install_deps.sh"
mow_build
mow_source_ws
MOW="${WS}/devel/lib/maximal_workspace/mow"
ROBOT="${REPO}/config/delta_like.yaml"
echo
echo "== mow info --robot config/delta_like.yaml"
"${MOW}" info --robot "${ROBOT}"
echo
OUT="${WS}/delta_like_eval.csv"
echo "== mow eval --robot config/delta_like.yaml --poses docs/examples/delta_like_poses.csv --out ${OUT}"
"${MOW}" eval --robot "${ROBOT}" --poses "${REPO}/docs/examples/delta_like_poses.csv" --out "${OUT}"
echo "columns x, y, z, inside and det_<mode> of ${OUT}:"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i ~ /^(x|y|z|inside|det_.*)$/) keep[++n] = i }
         { row = $keep[1]; for (k = 2; k <= n; k++) row = row "," $keep[k]; print row }' "${OUT}"
echo
echo "== mow workspace --robot config/delta_like.yaml --step 0.01 --out ${WS}/delta_like_workspace"
"${MOW}" workspace --robot "${ROBOT}" --step 0.01 --out "${WS}/delta_like_workspace"
echo
echo "== mow plan --robot config/delta_like.yaml --goal 0.775,0.455,0.075 (the Fig. 14 situation)"
"${MOW}" plan --robot "${ROBOT}" --goal 0.775,0.455,0.075 --out "${WS}/delta_like_plan.csv" --quiet
echo
echo "mow is at ${MOW}; after 'source ${WS}/devel/setup.bash' run it as 'rosrun maximal_workspace mow'."
echo
if [ -n "${DISPLAY:-}" ]; then
  echo "== roslaunch maximal_workspace demo.launch (rviz on ${DISPLAY}; Ctrl-C ends it)"
  roslaunch maximal_workspace demo.launch
else
  echo "== roslaunch maximal_workspace demo.launch rviz:=false exit_when_done:=true (no DISPLAY: headless)"
  roslaunch maximal_workspace demo.launch rviz:=false exit_when_done:=true
fi
