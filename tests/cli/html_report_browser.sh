#!/bin/sh
# ctest html_report_browser: writes the HTML report of the shipped plans with the built tool and
# checks it in headless Chromium with the network off (tools/report-web/browser-test.mjs).
# Needs Debian's chromium: `tools/setup --browser` installs it (tools/test does).
#   html_report_browser.sh TUBEPLAN SOURCE_DIR OUT_DIR
set -eu
tubeplan=$1 source=$2 out=$3
if [ ! -x "${CHROMIUM:-/usr/bin/chromium}" ]; then
  echo "html_report_browser: error: ${CHROMIUM:-/usr/bin/chromium} is missing; run tools/setup --browser (tools/test does)" >&2
  exit 1
fi
mkdir -p "$out"
status=0
"$tubeplan" evaluate "$source/plans" --html "$out/report.html" > "$out/evaluate.txt" || status=$?
# Exit 1: two shipped plans are infeasible by design.
[ "$status" -le 1 ] || { cat "$out/evaluate.txt"; exit 1; }
node "$source/tools/report-web/browser-test.mjs" "$out/report.html" "$out/report.png"
# The same page with each plan's first part (the floor) a mesh part of 10,092 triangles: drawn
# as the boxes are, the tube still seen through it.
node "$source/tools/report-web/browser-test.mjs" --mesh-part 29 "$out/report.html" "$out/report-mesh.png"
# A long recording (two minutes of free motion, tools/make-long-trajectory): its page is bounded
# (bins merged past 2048 a plan) and opens as the short one does; then the same page with its
# arrays stretched to those of an unbounded hour at 50 Hz (180 000 frames), which the page's
# script must walk without spreading them into a call.
"$source/tools/make-long-trajectory" 120 "$out/long" 2> /dev/null
status=0
"$tubeplan" evaluate "$out/long/long-120s.yaml" --html "$out/long.html" > "$out/long.txt" || status=$?
# Exit 1: the long free motion never reaches the goal.
[ "$status" -le 1 ] || { cat "$out/long.txt"; exit 1; }
node "$source/tools/report-web/browser-test.mjs" "$out/long.html"
node "$source/tools/report-web/browser-test.mjs" --stretch-frames 180000 "$out/long.html"
