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
