#!/usr/bin/env bash
# Looks at a `qvr run` report the way a reader's browser does: a full-page screenshot of
# report.html through headless Chromium (apt-get install chromium; not a build dependency), and
# a check that its <video> element loads the MP4. Usage: scripts/check_report.sh RUN_DIR [PNG]
set -euo pipefail
dir=$(cd "$1" && pwd)
png=${2:-$dir/report_screenshot.png}
browser=$(command -v chromium || command -v chromium-browser || true)
[ -n "$browser" ] || { echo "check_report: chromium not installed" >&2; exit 2; }
[ -f "$dir/report.html" ] || { echo "check_report: no $dir/report.html" >&2; exit 2; }
flags=(--headless --no-sandbox --disable-gpu)
"$browser" "${flags[@]}" --screenshot="$png" --window-size=1300,5200 "file://$dir/report.html" \
    >/dev/null 2>&1
if grep -q "<pre>" "$dir/report.html"; then
    echo "check_report: report.html holds a <pre> dump" >&2; exit 1
fi
# The same page with a script that reports whether the video's first frame decoded.
probe="$dir/.report_video_check.html"
trap 'rm -f "$probe"' EXIT
sed 's|</body></html>|<script>const v=document.querySelector("video");const r=document.createElement("pre");r.id="result";r.textContent="NO-VIDEO";document.body.appendChild(r);if(v){r.textContent="VIDEO-PENDING";v.addEventListener("loadeddata",()=>{r.textContent="VIDEO-OK "+v.videoWidth+"x"+v.videoHeight+" "+v.duration.toFixed(3)+" s";});v.addEventListener("error",()=>{r.textContent="VIDEO-ERROR";});v.load();}</script></body></html>|' \
    "$dir/report.html" >"$probe"
result=$("$browser" "${flags[@]}" --virtual-time-budget=8000 --dump-dom "file://$probe" 2>/dev/null |
    grep -o '<pre id="result">[^<]*' | sed 's/.*>//')
echo "check_report: screenshot $png; video: $result"
[[ $result == VIDEO-OK* ]]
