#!/usr/bin/env bash
# Regenerates the pictures of docs/seeing-a-fit.md in docs/pictures/ from bundled data
# (data/projector/misclicked.csv, data/projector/box.obj): the overlay, the fit report and the
# camproj view page's orbit view and view through the camera (headless Chromium, as the browser
# test runs it). Usage: bash scripts/docs_pictures.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/build.sh" >/dev/null
camproj=$root/build/release/apps/camproj
work=$root/build/docs_pictures
out=$root/docs/pictures
mkdir -p "$work" "$out"
cd "$root"
points=data/projector/misclicked.csv

"$camproj" fit "$points" --image-size 1920x1080 -o "$work/camera.json" --report "$out/fit_report.svg" >/dev/null
"$camproj" overlay "$work/camera.json" "$points" -o "$out/overlay.png"
# Run from the work folder, so that the page names the camera file as camera.json.
(cd "$work" && "$camproj" view camera.json "$root/$points" --mesh "$root/data/projector/box.obj" \
  -o view.html)

chromium=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -z "$chromium" ]]; then
  echo "docs_pictures: no Chromium (bash scripts/install-deps.sh installs it): view pictures not made" >&2
  exit 1
fi
shot() {  # shot FRAGMENT OUTPUT
  # A window of 1280x720: the report panel takes 380 px; the image's 16:9 fills the rest.
  timeout 60 "$chromium" --headless --no-sandbox --use-gl=swiftshader --enable-unsafe-swiftshader \
    --no-first-run --user-data-dir="$work/profile" --hide-scrollbars --window-size=1280,720 \
    --virtual-time-budget=8000 --screenshot="$2" "file://$work/view.html$1" 2>/dev/null
}
shot "" "$out/view_orbit.png"
shot "#through" "$out/view_through.png"
echo "docs_pictures: wrote $(cd "$out" && ls | tr '\n' ' ')"
