#!/usr/bin/env bash
# End-to-end tests of the built `camproj` binary: outputs, messages and exit codes.
# Usage: cli_test.sh CAMPROJ_BINARY DATA_DIR CASE   (ctest runs one CASE per test)
set -u
bin=$1
data=$2
case=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL [$case]: $*" >&2; exit 1; }
# expect_exit CODE CMD...: runs CMD, keeps stdout/stderr in $work/out, $work/err.
expect_exit() {
  local want=$1; shift
  "$@" >"$work/out" 2>"$work/err"
  local got=$?
  [[ $got -eq $want ]] || fail "exit $got, expected $want: $*\n--- stdout\n$(cat "$work/out")\n--- stderr\n$(cat "$work/err")"
}
expect_in() { grep -q -- "$2" "$work/$1" || fail "$1 lacks '$2':\n$(cat "$work/$1")"; }
expect_not_in() { ! grep -q -- "$2" "$work/$1" || fail "$1 has '$2':\n$(cat "$work/$1")"; }
py() { /usr/bin/python3 "$@"; }
# same_calibration A B: two calibration files with the same keys, names and strings, and numbers
# equal to 1e-12 relative: the intrinsics and poses come out bit for bit, but the covariance's
# (sigma, predicted_rms_px) last bits vary with where the inputs sit in memory (1-4 ulp measured,
# from the same points read from one file or from two).
same_calibration() {
  py - "$1" "$2" <<'PY'
import json, sys
def same(a, b, path):
    assert type(a) == type(b), path
    if isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a: same(a[k], b[k], path + "." + k)
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)): same(x, y, "%s[%d]" % (path, i))
    elif isinstance(a, float):
        assert abs(a - b) <= 1e-12 * max(abs(a), abs(b)), (path, a, b)
    else:
        assert a == b, (path, a, b)
a, b = (json.load(open(p)) for p in sys.argv[1:])
same(a, b, "")
for name in ("intrinsics", "views"):
    assert a[name] == b[name], name + " not bit for bit"
PY
}
# views_csv OUT FILE...: the single-view CSVs (X,Y,Z,u,v) as one CSV with a view column (each
# view named by its file's stem) and an id column numbering each view's rows, so that the ids
# repeat across views; the rows interleaved (row 1 of every view, then row 2, ...), so that a
# view's rows are not adjacent.
views_csv() {
  py - "$@" <<'PY'
import os, sys
views = []
for path in sys.argv[2:]:
    lines = [l.strip() for l in open(path) if l.strip() and not l.startswith("#")]
    assert lines[0] == "X,Y,Z,u,v", (path, lines[0])
    views.append((os.path.splitext(os.path.basename(path))[0], lines[1:]))
with open(sys.argv[1], "w") as out:
    out.write("view,id,X,Y,Z,u,v\n")
    for k in range(max(len(rows) for _, rows in views)):
        for name, rows in views:
            if k < len(rows):
                out.write("%s,%d,%s\n" % (name, k + 1, rows[k]))
PY
}

case $case in
  fit_projector)
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/cam.json" --trace
    # The projector's principal point is at the bottom edge and its pixels are square: the
    # automatic model frees the principal point and leaves the rest out, saying why.
    expect_in out "model: pose+focal+principal-point, 9 free parameters"
    expect_in out "fixed aspect = 1 (left out: BIC "
    grep -q '"left_out"' "$work/cam.json" || fail "camera file lacks left_out"
    grep -q '"selection"' "$work/cam.json" || fail "camera file lacks the model selection"
    # The covariance's linearity check, in words and in the file (fit.h LinearityCheck).
    expect_in out "^linearity: "
    grep -q '"worst_deviation"' "$work/cam.json" || fail "camera file lacks the linearity check"
    expect_in out "residuals: rms"
    expect_in out "worst points:"
    expect_in out "iteration  elapsed_us  rms_px"
    # The fit's time and the command's wall time (reading and writing included) are both printed.
    fit_ms=$(sed -n 's/^time: \([0-9.]*\) ms.*/\1/p' "$work/out")
    wall_ms=$(sed -n 's/^wall time: \([0-9.]*\) ms (reading 20 points.*/\1/p' "$work/out")
    [[ -n "$fit_ms" && -n "$wall_ms" ]] && py -c "import sys; sys.exit(not float(sys.argv[1]) <= float(sys.argv[2]))" "$fit_ms" "$wall_ms" \
      || fail "fit time '$fit_ms' ms and wall time '$wall_ms' ms"
    [[ -f "$work/cam.json" ]] || fail "no camera file"
    grep -q '"fit"' "$work/cam.json" || fail "camera file lacks fit"
    expect_exit 0 "$bin" export "$work/cam.json" --to gl
    expect_in out "^projection "
    # An orthographic model the points refuse: no outlier search ran, and the refusal says so
    # (it said RANSAC "found no camera that most points agree on ()").
    expect_exit 3 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --model orthographic+aspect
    expect_in err "RANSAC, which samples perspective cameras only, did not run for the orthographic model"
    ;;
  fit_json_stdout)
    expect_exit 0 "$bin" fit "$data/synthetic/points.csv" --image-size 1280x800 --json
    expect_in out '"rms_px"'
    expect_in out '"cam_from_world"'
    # With --trace the trace goes to stderr: stdout stays one JSON document.
    expect_exit 0 "$bin" fit "$data/synthetic/points.csv" --image-size 1280x800 --json --trace
    py -c 'import json, sys; json.load(open(sys.argv[1]))' "$work/out" || fail "stdout is not one JSON document"
    expect_in err "iteration"
    ;;
  fit_planar_refused_then_fixed)
    expect_exit 3 "$bin" fit "$data/plane/points.csv" --image-size 1280x720 --model focal+aspect+principal-point -o "$work/cam.json"
    expect_in err "coplanar"
    expect_in err "principal point"
    [[ ! -e "$work/cam.json" ]] || fail "a refused fit wrote a camera file"
    expect_exit 0 "$bin" fit "$data/plane/points.csv" --image-size 1280x720 --model focal -o "$work/cam.json"
    expect_in out "coplanar"
    # Automatic: the plane cannot determine the principal point, and says so.
    expect_exit 0 "$bin" fit "$data/plane/points.csv" --image-size 1280x720
    expect_in out "fixed principal point = 639.5, 359.5 (left out: not determined"
    ;;
  fit_known_intrinsics)
    expect_exit 0 "$bin" fit "$data/synthetic/points.csv" --image-size 1280x800 --intrinsics "$data/synthetic/truth.json"
    expect_in out "model: pose, 6 free parameters"
    expect_in out "given: pose only"
    ;;
  fit_fovy_fixes_the_field_of_view)
    # --fovy fixes fy (and fx = fy at aspect 1) in the automatic model too: the ladder freed the
    # aspect, and so fy, writing 45.09 degrees for --fovy 45.5.
    for model in auto principal-point; do
      expect_exit 0 "$bin" fit "$data/synthetic/points.csv" --image-size 1280x800 --fovy 45.5 \
        --model "$model" -o "$work/fovy.json"
      py - "$work/fovy.json" <<'PY' || fail "--model $model: the field of view is not --fovy's"
import json, math, sys
k = json.load(open(sys.argv[1]))["intrinsics"]
fovy = 2 * math.degrees(math.atan(400 / k["fy"]))
sys.exit(0 if abs(fovy - 45.5) < 1e-12 and k["fx"] == k["fy"] else 1)
PY
    done
    ;;
  fit_summary_in_the_users_pixel_origin)
    # With --pixel-origin corner the summary's cx, cy (intrinsics, sigmas, a fixed principal
    # point) are the file's, in the corner convention (they were printed in the centre's); and a
    # forced --model says that it, not the user, held the intrinsics it leaves out (they were
    # "(given)").
    expect_exit 0 "$bin" synth --seed 1 --points 30 --noise 0.5 -o "$work/c.csv" --truth "$work/t.json"
    expect_exit 0 "$bin" fit "$work/c.csv" --image-size 1920x1080 --model focal --pixel-origin corner -o "$work/c.json"
    expect_in out "fixed principal point = 960, 540 (default: not in --model focal)"
    expect_in out "fixed aspect = 1 (default: not in --model focal)"
    expect_in out " cx 960 cy 540 (px, pixel corners at integers)"
    py -c "
import json, sys
fixed = json.load(open(sys.argv[1]))['fit']['fixed']
assert {'name': 'principal point', 'value': '960, 540 (default: not in --model focal)'} in fixed, fixed
" "$work/c.json" || fail "the camera file's fixed principal point is not the summary's"
    expect_exit 0 "$bin" fit "$work/c.csv" --image-size 1920x1080 --model focal+principal-point \
      --skew 0 --pixel-origin corner -o "$work/c.json"
    expect_in out "fixed skew = 0 (given)"
    expect_in out "fixed k1 = 0 (default: not in --model focal+principal-point)"
    py - "$work/c.json" "$work/out" <<'PY' || fail "the summary's cx, cy are not the file's"
import json, re, sys
camera = json.load(open(sys.argv[1]))
assert camera["pixel_origin"] == "corner"
k = camera["intrinsics"]
text = open(sys.argv[2]).read()
line = re.search(r"intrinsics: fx \S+ fy \S+ cx (\S+) cy (\S+) \(px, pixel corners", text)
assert line and float(line.group(1)) == float("%.6g" % k["cx"]), (line, k)
assert float(line.group(2)) == float("%.6g" % k["cy"]), (line, k)
for name in ("cx", "cy"):
    value = float(re.search(r"  %s = (\S+) \+- " % name, text).group(1))
    assert abs(value - k[name]) < 0.05, (name, value, k[name])  # to the printed digits
PY
    ;;
  fit_bad_csv_names_line_and_column)
    printf 'X,Y,Z,u,v\n1,2,3,4,5\n1,2,abc,4,5\n' >"$work/bad.csv"
    expect_exit 2 "$bin" fit "$work/bad.csv" --image-size 640x480
    expect_in err "bad.csv: line 3, column 3 (Z)"
    printf '' >"$work/empty.csv"
    expect_exit 2 "$bin" fit "$work/empty.csv" --image-size 640x480
    expect_in err "empty file"
    printf 'X,Y,Z,u\n1,2,3,4\n' >"$work/missing.csv"
    expect_exit 2 "$bin" fit "$work/missing.csv" --image-size 640x480
    expect_in err "header lacks column v"
    printf 'X,Y,Z,u,v\n1,2,nan,4,5\n' >"$work/nan.csv"
    expect_exit 2 "$bin" fit "$work/nan.csv" --image-size 640x480
    expect_in err "not finite"
    printf 'X,Y,Z,u,X\n1,2,3,4,5\n' >"$work/dup.csv"
    expect_exit 2 "$bin" fit "$work/dup.csv" --image-size 640x480
    expect_in err "duplicate column"
    # A 2 MB line stands for the 3 GB one: refused after ~1 MiB, whatever the file's size.
    { printf 'X,Y,Z,u,v\n'; head -c 2000000 /dev/zero | tr '\0' 1; printf '\n'; } >"$work/long.csv"
    expect_exit 2 "$bin" fit "$work/long.csv" --image-size 640x480
    expect_in err "line 2 is longer than 1048576 bytes"
    ;;
  fit_failure_keeps_existing_camera_file)
    cp "$data/projector/truth.json" "$work/cam.json"
    printf 'X,Y,Z,u,v\n1,2,3,4,5\n' >"$work/few.csv"
    expect_exit 3 "$bin" fit "$work/few.csv" --image-size 640x480 -o "$work/cam.json"
    # Why, then what to do on a line of its own.
    expect_in err "^camproj: cannot fit: 1 points give 2 equations"
    expect_in err "^camproj: to fix: Add points (at least"
    cmp -s "$data/projector/truth.json" "$work/cam.json" || fail "the old camera file was changed"
    [[ $(ls "$work" | grep -c tmp) -eq 0 ]] || fail "a temporary file was left behind"
    ;;
  fit_ransac_lists_misclicked_points)
    # Points 3 and 7 of the synthetic scene moved by 200 px: RANSAC names them.
    awk -F, 'BEGIN { OFS = "," } /^[-0-9]/ { row++; if (row == 3 || row == 7) $4 += 200 } { print }' \
      "$data/synthetic/points.csv" >"$work/clicked.csv"
    expect_exit 0 "$bin" fit "$work/clicked.csv" --image-size 1280x800 --ransac 4 -o "$work/cam.json"
    expect_in out "left out of the fit (found by ransac): 2 of 50 points"
    # The model line counts the points fitted (it said 50).
    expect_in out "^model: .*, 48 of 50 points, "
    expect_in out "  3 is "
    expect_in out "  7 is "
    grep -q '"outliers"' "$work/cam.json" || fail "camera file lacks the outliers"
    # A forced model is no automatic choice (the summary said "chosen automatically by BIC").
    expect_exit 0 "$bin" fit "$work/clicked.csv" --image-size 1280x800 --model focal+principal-point
    expect_in out "^  the only model open; BIC at pixel noise"
    expect_not_in out "chosen automatically"
    ;;
  fit_batch_reports_every_file)
    mkdir -p "$work/in"
    cp "$data/projector/points.csv" "$work/in/projector.csv"
    cp "$data/synthetic/points.csv" "$work/in/synthetic.csv"
    cp "$data/plane/points.csv" "$work/in/plane.csv"
    printf 'X,Y,Z,u,v\n0,0,0,1,1\n1,1,1,2,2\n2,2,2,3,3\n3,3,3,4,4\n4,4,4,5,5\n5,5,5,6,6\n7,7,7,8,8\n' >"$work/in/line.csv"  # collinear: refused (exit 3)
    printf 'X,Y,Z,u,v\n1,2,x,4,5\n' >"$work/in/broken.csv"     # bad input (exit 2)
    expect_exit 3 "$bin" fit "$work/in" --image-size 1920x1080 -o "$work/out_cams" --jobs 2
    expect_in out "projector.csv	ok	pose+focal+principal-point"
    expect_in out "synthetic.csv	ok"
    # The plane was shot at 1280x720: at 1920x1080 its principal point is assumed 320 px off, and
    # the camera RANSAC finds leaves out most points (it had been answered so: 16 of its 30 points
    # left out and k1 -0.25, a wrong camera).
    expect_in out "plane.csv	refused	.*leaves out [0-9]* of the 30 points, more than half"
    expect_in out "plane.csv	refused	.*Check the image size"
    expect_in out "line.csv	refused	the 3D points are collinear"
    expect_in out "broken.csv	bad input	.*line 2, column 3 (Z)"
    expect_in out "2 of 5 fitted"
    [[ -f "$work/out_cams/projector.json" && -f "$work/out_cams/synthetic.json" ]] || fail "missing camera files"
    [[ ! -e "$work/out_cams/line.json" && ! -e "$work/out_cams/broken.json" && ! -e "$work/out_cams/plane.json" ]] ||
      fail "camera file for a failed input"
    expect_exit 1 "$bin" fit "$work/in/projector.csv" "$work/in/synthetic.csv" --image-size 1920x1080
    expect_in err "needs -o"
    # --json: a refusal's line carries the fix apart too.
    expect_exit 3 "$bin" fit "$work/in/line.csv" "$work/in/projector.csv" --image-size 1920x1080 \
      -o "$work/json_cams" --json
    expect_in out '"file":"[^"]*line.csv".*"fix":"Add points off the line"'
    ;;
  fit_object_points)
    # Scene 64 of the click benchmark (clean, 7 points): pose + focal explains the clicks, 35 px
    # off at the building's back corners (a lens shift traded for the focal length). The default
    # refuses it, saying how to state the principal point; stated at the centre it is answered
    # (the user's word: wrong for this projector, but no longer a guess).
    cat >"$work/clicks.csv" <<'EOF'
X,Y,Z,u,v
-0.4263201812450911,-1.453950580074489,0.6139920699269872,1118,542
-0.4263201812450911,1.453950580074489,0,894,800
0.4164750327061282,0.8215297769328793,0.6139920699269872,805,627
-0.4263201812450911,-1.453950580074489,0,1115,642
-0.41637474531839747,-0.31569315730135905,0.6139920699269872,1037,592
-0.4263201812450911,1.453950580074489,0.6139920699269872,892,685
0.4263201812450911,1.453950580074489,0,746,774
EOF
    cat >"$work/vertices.csv" <<'EOF'
X,Y,Z
-0.4263201812450911,-1.453950580074489,0
0.4263201812450911,-1.453950580074489,0
-0.4263201812450911,1.453950580074489,0
0.4263201812450911,1.453950580074489,0
-0.4263201812450911,-1.453950580074489,0.6139920699269872
0.4263201812450911,-1.453950580074489,0.6139920699269872
-0.4263201812450911,1.453950580074489,0.6139920699269872
0.4263201812450911,1.453950580074489,0.6139920699269872
-0.41637474531839747,-0.31569315730135905,0.6139920699269872
0.4164750327061282,-0.31569315730135905,0.6139920699269872
-0.41637474531839747,0.8215297769328793,0.6139920699269872
0.4164750327061282,0.8215297769328793,0.6139920699269872
-0.41637474531839747,-0.31569315730135905,2.9628547177087423
0.4164750327061282,-0.31569315730135905,2.9628547177087423
-0.41637474531839747,0.8215297769328793,2.9628547177087423
0.4164750327061282,0.8215297769328793,2.9628547177087423
EOF
    expect_exit 3 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 -o "$work/cam.json"
    expect_in err "cannot tell where the principal point is"
    expect_in err "give --fix principal-point"
    [[ ! -e "$work/cam.json" ]] || fail "a camera file for a refusal"
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point -o "$work/cam.json"
    # Judged over the clicks' box alone, the summary says how to have it judged beyond them.
    expect_in out "^note: the camera is judged (--max-uncertainty) over the box the points span only, and extrapolated beyond it: give --bounds-mesh model.obj (or .ply) or --object-points"
    # The clicks themselves as object points: the same camera, judged over "the object points" too.
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point \
      --object-points "$work/clicks.csv"
    expect_in out "over the box the points span and the object points"
    expect_not_in out "^note: the camera is judged"
    # A bad object file is named; a robust loss, which skips the determination check, is refused.
    printf 'X,Y\n1,2\n' >"$work/bad.csv"
    expect_exit 2 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/bad.csv"
    expect_in err "bad.csv"
    expect_exit 1 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/vertices.csv" \
      --model focal --loss huber:2
    expect_in err "object-points"
    # The object points are an input: a camera file written over them is refused, and they survive.
    cp "$work/vertices.csv" "$work/vertices.before"
    expect_exit 2 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/vertices.csv" \
      -o "$work/vertices.csv"
    cmp -s "$work/vertices.csv" "$work/vertices.before" || fail "the object points file was replaced"
    # The model's mesh (--bounds-mesh) is judged at as its vertices are with --object-points: the
    # same camera and the same fit record (its time aside), near and far from the mesh's box, and
    # no note.
    tail -n +2 "$work/vertices.csv" | tr ',' ' ' | sed 's/^/v /' >"$work/model.obj"
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point \
      --object-points "$work/vertices.csv" -o "$work/by_points.json"
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point \
      --bounds-mesh "$work/model.obj" -o "$work/by_mesh.json"
    expect_in out "over the box the points span and the object points"
    expect_not_in out "^note: the camera is judged"
    py - "$work/by_points.json" "$work/by_mesh.json" <<'PY' || fail "--bounds-mesh judged otherwise than --object-points"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
for c in (a, b):
    del c["fit"]["time_ms"]
same = all(a[k] == b[k] for k in ("cam_from_world", "intrinsics", "fit"))
sys.exit(0 if same and a["frustum"] != b["frustum"] else 1)
PY
    # Given both, the object points are judged at, not the mesh's vertices: the determination
    # reads as with those object points alone. A robust loss takes the mesh for near and far.
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point \
      --object-points "$work/clicks.csv" -o "$work/by_clicks.json"
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --fix principal-point \
      --bounds-mesh "$work/model.obj" --object-points "$work/clicks.csv" -o "$work/both.json"
    py -c "import json, sys; a, b = (json.load(open(f))['fit']['determination'] for f in sys.argv[1:]); sys.exit(a != b)" \
      "$work/by_clicks.json" "$work/both.json" || fail "--object-points with --bounds-mesh judged at the mesh"
    py -c "import json, sys; a, b = (json.load(open(f))['fit']['determination'] for f in sys.argv[1:]); sys.exit(a == b)" \
      "$work/by_clicks.json" "$work/by_mesh.json" || fail "the mesh's vertices judged as the clicks alone"
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --bounds-mesh "$work/model.obj" \
      --model focal --loss huber:2
    cp "$work/model.obj" "$work/model.before"
    expect_exit 2 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --bounds-mesh "$work/model.obj" \
      -o "$work/model.obj"
    cmp -s "$work/model.obj" "$work/model.before" || fail "the mesh file was replaced"
    ;;
  fit_robust_loss)
    # A robust loss runs with a forced model (Ceres, said in the summary); the automatic
    # selection compares least-squares fits and refuses it with the reason.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --model focal+aspect+principal-point --loss huber:2 -o "$work/cam.json"
    expect_in out "iterations of ceres, huber loss 2 px"
    [[ -f "$work/cam.json" ]] || fail "no camera file"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080
    expect_in out "iterations of levenberg-marquardt"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --loss huber:2
    expect_in err "--loss needs an explicit --model"
    ;;
  usage_errors)
    expect_exit 1 "$bin"
    expect_exit 1 "$bin" fit "$data/projector/points.csv"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920by1080
    expect_in err "WIDTHxHEIGHT"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --free focus
    expect_exit 1 "$bin" export "$data/projector/truth.json" --to vrml
    # Non-finite and out-of-range option values are refused, naming the option and the value
    # (NaN went through CLI11's PositiveNumber and was taken as not given; session 37).
    local_points="$data/projector/points.csv"
    for option in --focal --fovy --aspect --sigma --max-uncertainty --ransac --near --far \
                  --skew --k1 --k2; do
      expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 "$option" nan
      expect_in err "^$option: \"nan\" is not a finite number"
    done
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --focal -1
    expect_in err "^--focal: must be positive, got -1"
    # convert: a bad value names its option (exit 1, as every bad option value; it was exit 2,
    # "fx must be positive"), and options the conversion does not read are refused, not dropped.
    expect_exit 1 "$bin" convert --intrinsics -500,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum
    expect_in err "^camproj: usage: --intrinsics: fx must be positive, got -500"
    expect_exit 1 "$bin" convert --frustum 1,-1,-1,1,0.1,10 --image-size 1920x1080 --to gl
    expect_in err "^camproj: usage: --frustum: frustum left must be less than right"
    expect_exit 1 "$bin" convert --intrinsics 1000,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum --depth zo
    expect_in err "^camproj: usage: --depth and --reversed-z go with --to gl"
    expect_exit 1 "$bin" convert --frustum -0.096,0.096,-0.054,0.054,0.1,100 --image-size 1920x1080 --to perspective --pixel-origin corner
    expect_in err "^camproj: usage: --pixel-origin is the convention of cx, cy"
    # A seed is a uint64 as written: -1 was taken as 2^64 - 1, 2^64 and beyond capped there.
    for seed in -1 18446744073709551616 1e3; do
      expect_exit 1 "$bin" synth --seed "$seed" -o "$work/s.csv" --truth "$work/t.json"
      expect_in err "^--seed: must be a whole number from 0 to 18446744073709551615, got $seed"
    done
    [[ ! -e "$work/s.csv" ]] || fail "a refused synth wrote its points"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --far inf
    expect_in err "^--far: \"inf\" is not a finite number"
    expect_exit 1 "$bin" export "$data/projector/truth.json" --to gl --near nan
    expect_in err "^--near: \"nan\" is not a finite number"
    expect_exit 1 "$bin" synth --noise nan -o "$work/p.csv" --truth "$work/t.json"
    expect_in err "^--noise: \"nan\" is not a finite number"
    expect_exit 1 "$bin" calibrate "$data/real/opencv_chessboard/left01.csv" --image-size 640x480 \
        -o "$work/c.json" --sigma 0
    expect_in err "^--sigma: must be positive, got 0"
    [[ ! -e "$work/p.csv" && ! -e "$work/c.json" ]] || fail "a refused option left a file"
    # Options that would be dropped are refused (before session 37 each was ignored, exit 0):
    # a value beside --intrinsics, intrinsics of another image size, --skew/--near/--far with
    # --frustum; and an image side the camera files cannot record.
    truth="$data/projector/truth.json"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --intrinsics "$truth" --focal 1000 --k1 0
    expect_in err "usage: --intrinsics gives every intrinsic (the pose alone is fitted): leave out --focal, --k1, or leave out --intrinsics"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --intrinsics "$truth" --model focal+principal-point
    expect_in err "leave out --model focal+principal-point"
    expect_exit 1 "$bin" fit "$local_points" --image-size 640x480 --intrinsics "$truth"
    expect_in err "usage: --intrinsics .*truth.json is for a 1920x1080 image, but --image-size is 640x480"
    expect_exit 0 "$bin" fit "$local_points" --image-size 1920x1080 --intrinsics "$truth" --model pose
    # An intrinsic both freed and fixed was fixed silently, the later option winning (session 40).
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --free aspect --aspect 1.01 -o "$work/c.json"
    expect_in err "usage: aspect is both freed (--free aspect) and fixed (--aspect 1.01): give one"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --model focal+k1 --fix k1 -o "$work/c.json"
    expect_in err "usage: k1 is both freed (--model focal+k1) and fixed (--fix k1): give one"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --model focal+aspect --fovy 40 -o "$work/c.json"
    expect_in err "usage: focal is both freed (--model focal+aspect) and fixed (--fovy 40): give one"
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --free aspect --fovy 40 -o "$work/c.json"
    expect_in err "usage: aspect is both freed (--free aspect) and fixed (--fovy 40): give one"
    # A model naming a group twice was taken as naming it once.
    expect_exit 1 "$bin" fit "$local_points" --image-size 1920x1080 --model focal+focal -o "$work/c.json"
    expect_in err "usage: --model: \"focal\" is named twice in \"focal+focal\""
    expect_exit 1 "$bin" calibrate "$data/real/opencv_chessboard/left01.csv" --image-size 640x480 \
      --model principal-point+k1+principal-point -o "$work/c.json"
    expect_in err "group \"principal-point\" is named twice in \"principal-point+k1+principal-point\""
    [[ ! -e "$work/c.json" ]] || fail "a refused option left a file"
    expect_exit 1 "$bin" convert --frustum -0.05,0.05,-0.05,0.05,0.1,1 --image-size 100x100 --to gl --near 5
    expect_in err "usage: --skew, --near and --far go with --intrinsics"
    expect_exit 1 "$bin" fit "$local_points" --image-size 2000000x1000
    expect_in err "usage: --image-size: at most 1000000 px per side"
    expect_exit 1 "$bin" synth --image-size 1000x2000000 -o "$work/p.csv" --truth "$work/t.json"
    # Conversions whose results overflow a double are refused, never printed as inf or 0.
    expect_exit 2 "$bin" convert --frustum -1e-310,1e-310,-0.1,0.1,0.1,1 --image-size 100x100 --to intrinsics
    expect_in err "the frustum's intrinsics are not finite"
    expect_exit 2 "$bin" convert --intrinsics 100,100,49.5,49.5 --image-size 100x100 --near 0.1 --far 1 --to gl --skew 1e308
    expect_in err "the projection matrix of fx = 100, fy = 100 on a 100x100 image with near 0.1.* cannot be represented in a double"
    expect_exit 1 "$bin" convert --frustum -1e308,1e308,-0.1,0.1,1e-308,1 --image-size 100x100 --to gl
    expect_in err "^camproj: usage: --frustum: the frustum's width and height must be finite"
    expect_exit 2 "$bin" convert --intrinsics 100,100,1e308,50 --image-size 100x100 --near 0.1 --far 1 --to frustum
    expect_in err "frustum left must be less than right"
    expect_exit 0 "$bin" --help
    expect_in out "Exit codes"
    expect_exit 0 "$bin" fit --help
    expect_in out "Examples"
    ;;
  stdout_write_errors)
    # A standard output that cannot be written (a full disk: /dev/full; a closed descriptor) is
    # exit 2 naming it, never a truncated output with exit 0 (it was, before session 37).
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/cam.json"
    "$bin" export "$work/cam.json" --to gl >/dev/full 2>"$work/err"
    code=$?
    [[ $code -eq 2 ]] || fail "export to /dev/full: exit $code, expected 2"
    expect_in err "camproj: error: cannot write the standard output: No space left on device"
    "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 >&- 2>"$work/err"
    code=$?
    [[ $code -eq 2 ]] || fail "fit with stdout closed: exit $code, expected 2"
    expect_in err "cannot write the standard output: Bad file descriptor"
    # A refusal keeps its own exit code (3) and says both.
    awk -F, 'BEGIN { OFS = "," } NR <= 2 { print; next } { $1 = -$1; print }' \
        "$data/projector/points.csv" >"$work/mirrored.csv"
    "$bin" fit "$work/mirrored.csv" --image-size 1920x1080 >/dev/full 2>"$work/err"
    code=$?
    [[ $code -eq 3 ]] || fail "a refusal with stdout full: exit $code, expected 3:\n$(cat "$work/err")"
    expect_in err "cannot fit"
    # Nothing written to a closed stdout is no error; a file written with -o is not affected.
    expect_exit 0 "$bin" export "$work/cam.json" --to gl -o "$work/gl.txt"
    "$bin" export "$work/cam.json" --to gl -o "$work/gl2.txt" >&- 2>/dev/null
    code=$?
    [[ $code -eq 0 ]] || fail "export -o with stdout closed: exit $code, expected 0"
    cmp -s "$work/gl.txt" "$work/gl2.txt" || fail "export -o with stdout closed wrote another file"
    ;;
  export_formats)
    for to in gl glm opencv-yaml colmap three json; do
      expect_exit 0 "$bin" export "$data/projector/truth.json" --to "$to"
      [[ -s "$work/out" ]] || fail "empty $to export"
    done
    expect_exit 0 "$bin" export "$data/projector/truth.json" --to gl --depth zo --reversed-z --infinite-far
    expect_in out "reversed-Z"
    expect_exit 2 "$bin" export "$work/none.json"
    expect_in err "none.json"
    printf '{"image_size": [640, 480],\n "intrinsics": {"fx": 1e400}}' >"$work/bad.json"
    expect_exit 2 "$bin" export "$work/bad.json"
    expect_in err "bad.json"
    ;;
  fit_bounds_cover_the_model)
    # Default: near and far come from the fitted points only, and the summary says so.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080
    expect_in out "^note: near .*cover the fitted points' depths only, widened by 10 %.*--bounds"
    # The points file has no ids: its row numbers name the points, as "point N" in sentences.
    expect_in out "^reliability: least checked: point [0-9]*, "
    # One plane given: it as given, the other from the points (the note said both were).
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --near 1.2
    expect_in out "^note: near 1.2, far .*: near as given (--near); far covers the fitted points' depths only, widened by 10 %.*--far as well"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --far 2
    expect_in out "^note: near .*, far 2: far as given (--far); near covers the fitted points' depths only"
    expect_not_in out "clips"
    # The advice's bound is rounded away from the points: point 8 is at depth 1.3237484 of the
    # mis-click scene's camera, and "below 1.32375" (to nearest) would not be below it.
    expect_exit 0 "$bin" fit "$data/projector/misclicked.csv" --image-size 1920x1080 --near 1.323749
    expect_in out "clips 1 of the 18 fitted points, nearer than it (point 8 at depth 1.32375): .* give --near below 1.32374 to draw them"
    # Given planes between the points' depths (1.317 to 1.794) clip some: the note counts them,
    # the farthest beyond each plane first, checked against the written camera's depths.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --near 1.35 \
      --far 1.4 -o "$work/clipped.json"
    py - "$work/clipped.json" "$data/projector/points.csv" "$work/out" <<'PY' || fail "the clipped-points notes do not match the camera's depths"
import csv, json, re, sys
c = json.load(open(sys.argv[1]))
R, t = c["cam_from_world"]["R"], c["cam_from_world"]["t"]
rows = list(csv.DictReader(l for l in open(sys.argv[2]) if not l.startswith("#")))
depth = {str(i + 1): sum(R[2][k] * float(r[a]) for k, a in enumerate("XYZ")) + t[2]
         for i, r in enumerate(rows)}
near = sorted((d, i) for i, d in depth.items() if d < 1.35)
far = sorted(((d, i) for i, d in depth.items() if d > 1.4), reverse=True)
out = open(sys.argv[3]).read()
want = [f"note: --near 1.35 clips {len(near)} of the 20 fitted points, nearer than it "
        f"(point {near[0][1]} at depth {near[0][0]:.6g}, point {near[1][1]} at {near[1][0]:.6g}",
        f"note: --far 1.4 clips {len(far)} of the 20 fitted points, farther than it "
        f"(point {far[0][1]} at depth {far[0][0]:.6g}, point {far[1][1]} at {far[1][0]:.6g}",
        f"give --near below {near[0][0]:.6g} to draw them",
        f"give --far beyond {far[0][0]:.6g} to draw them"]
missing = [w for w in want if w not in out]
print(missing)
sys.exit(1 if missing or not near or not far else 0)
PY
    # A given plane past every point is refused with the answer's depths (1.317 to 1.794 m).
    expect_exit 3 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --near 1.85
    expect_in err "every point is nearer than the given near plane 1.85: the fitted camera sees the points at depths 1.31"
    # --bounds-mesh: the box's 8 corners' depths, widened by 10 % (docs: the fit's margin rule),
    # checked against the written camera to 1e-12 relative (the same doubles, a few roundings).
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds-mesh "$data/projector/box.obj" -o "$work/mesh.json"
    expect_in out "^note: near .*cover the --bounds box (its 8 corners' depths, widened by 10 %)"
    expect_not_in out "clips"
    # A box smaller than the points: its near plane clips the nearest, and the note says how to
    # keep them.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds=-0.1,-0.1,-0.1,0.1,0.1,0.1
    expect_in out "^note: the near plane .* (covering the --bounds box) clips [0-9]* of the 20 fitted points, nearer than it (.*): an OpenGL render of this camera draws them nowhere; widen --bounds to hold them, or give --near below "
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds=-0.5,-0.3,-0.4,0.5,0.3,0.4 -o "$work/box.json"
    py -c "import json, sys; a, b = (json.load(open(f))['frustum'] for f in sys.argv[1:]); sys.exit(not (a['near'], a['far']) == (b['near'], b['far']))" \
      "$work/mesh.json" "$work/box.json" || fail "--bounds-mesh box.obj and --bounds of its box differ"
    py - "$work/mesh.json" <<'PY' || fail "near/far do not cover the box's corners"
import itertools, json, sys
c = json.load(open(sys.argv[1]))
R, t = c["cam_from_world"]["R"], c["cam_from_world"]["t"]
depths = [sum(R[2][i] * p[i] for i in range(3)) + t[2]
          for p in itertools.product((-0.5, 0.5), (-0.3, 0.3), (-0.4, 0.4))]
near, far = c["frustum"]["near"], c["frustum"]["far"]
want_near, want_far = min(depths) / 1.1, max(depths) * 1.1
ok = abs(near - want_near) <= 1e-12 * want_near and abs(far - want_far) <= 1e-12 * want_far
print(near, want_near, far, want_far)
sys.exit(0 if ok else 1)
PY
    # The same box's corners as PLY meshes: ascii, and binary (little- and big-endian, a
    # colour property between the coordinates, a face element before the vertices; x as float32,
    # exact at +-0.5): the same near and far as --bounds.
    py - "$work" <<'PY'
import itertools, struct, sys
corners = list(itertools.product((-0.5, 0.5), (-0.3, 0.3), (-0.4, 0.4)))
head = "ply\nformat {}\ncomment a face first\nelement face 1\nproperty list uchar int vertex_indices\n" \
       "element vertex 8\nproperty float x\nproperty uchar red\nproperty double y\nproperty double z\nend_header\n"
with open(sys.argv[1] + "/box_ascii.ply", "w") as f:
    f.write(head.format("ascii 1.0") + "3 0 1 2\n" + "".join(f"{x} 7 {y} {z}\n" for x, y, z in corners))
for name, order in (("le", "<"), ("be", ">")):
    fmt = "binary_little_endian 1.0" if order == "<" else "binary_big_endian 1.0"
    data = struct.pack(order + "B3i", 3, 0, 1, 2) + b"".join(
        struct.pack(order + "fBdd", x, 7, y, z) for x, y, z in corners)
    open(f"{sys.argv[1]}/box_{name}.ply", "wb").write(head.format(fmt).encode() + data)
PY
    for ply in box_ascii box_le box_be; do
      expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
        --bounds-mesh "$work/$ply.ply" -o "$work/$ply.json"
      py -c "import json, sys; a, b = (json.load(open(f))['frustum'] for f in sys.argv[1:]); sys.exit(not (a['near'], a['far']) == (b['near'], b['far']))" \
        "$work/$ply.json" "$work/box.json" || fail "--bounds-mesh $ply.ply and --bounds of its box differ"
    done
    head -c -10 "$work/box_le.ply" >"$work/cut.ply"  # the last vertex cut short
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds-mesh "$work/cut.ply"
    expect_in err "cut.ply: PLY: the data ends before the header's elements do"
    printf 'ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n' >"$work/noz.ply"
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds-mesh "$work/noz.ply"
    expect_in err "noz.ply: PLY: the vertex element has no scalar property z"
    # --near given: only far from the box.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds=-0.5,-0.3,-0.4,0.5,0.3,0.4 --near 0.5
    expect_in out "^note: near 0.5, far .*; near as given"
    # A box around the camera: corners behind it, no near plane covers it.
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds=-10,-10,-10,10,10,10 -o "$work/around.json"
    expect_in err "--bounds: the box's corner (.*) is at depth -.*give --near"
    [[ ! -e "$work/around.json" ]] || fail "a refused --bounds wrote a camera file"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds=-10,-10,-10,10,10,10 --near 0.1
    # Bad boxes and files.
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds 1,2,3
    expect_in err "--bounds"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds 1,0,0,0,1,1
    expect_in err "--bounds: box min must be <= max"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 \
      --bounds 0,0,0,1,1,1 --bounds-mesh "$data/projector/box.obj"
    printf 'f 1 2 3\n' >"$work/empty.obj"
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds-mesh "$work/empty.obj"
    expect_in err "empty.obj"
    printf 'v 0 0 0\nv 1 x 1\n' >"$work/bad.obj"
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --bounds-mesh "$work/bad.obj"
    expect_in err "bad.obj.*2"
    ;;
  export_gl_headers)
    # Every GL-facing export states the pixel convention and whether it holds the whole camera.
    expect_exit 0 "$bin" export "$data/projector/truth.json" --to gl
    expect_in out "^# pixels: GL window x = u + 0.5, y = 1080 - (v + 0.5) for camproj's kCenter pixel"
    expect_in out "^# distortion: none"
    expect_exit 0 "$bin" export "$data/projector/truth.json" --to glm
    expect_in out "^// pixels: GL window x = u + 0.5"
    expect_exit 0 "$bin" export "$data/projector/truth.json" --to three
    expect_in out "camproj's kCenter pixel + 0.5"
    # three: the depth advice is three's renderer options, not glClipControl.
    expect_in err "reversedDepthBuffer: true"
    expect_in err "logarithmicDepthBuffer: true"
    ! grep -q glClipControl "$work/err" || fail "--to three advises glClipControl:\n$(cat "$work/err")"
    # A distorted camera (k1 = -0.15, k2 = 0.02): header and stderr say the matrix drops it and by
    # how much at the worst image corner. Expected: the pinhole ray through each outer corner,
    # distorted, against the corner (docs/exports.md), to the 3 digits printed.
    py - "$data/projector/truth.json" "$work/lens.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["intrinsics"]["k1"], c["intrinsics"]["k2"] = -0.15, 0.02
for key in ("gl", "look_at"):
    c.pop(key, None)
json.dump(c, open(sys.argv[2], "w"))
k = c["intrinsics"]; W, H = c["image_size"]
worst = 0
for u, v in ((-0.5, -0.5), (W - 0.5, -0.5), (-0.5, H - 0.5), (W - 0.5, H - 0.5)):
    y = (v - k["cy"]) / k["fy"]; x = (u - k["cx"] - k["skew"] * y) / k["fx"]
    r2 = x * x + y * y; d = 1 + k["k1"] * r2 + k["k2"] * r2 * r2
    du, dv = k["fx"] * d * x + k["skew"] * d * y + k["cx"] - u, k["fy"] * d * y + k["cy"] - v
    worst = max(worst, (du * du + dv * dv) ** 0.5)
open(sys.argv[2] + ".px", "w").write("%.3g" % worst)
PY
    px=$(cat "$work/lens.json.px")
    for to in gl glm three; do
      expect_exit 0 "$bin" export "$work/lens.json" --to "$to" --quiet
      expect_in out "k1 = -0.15, k2 = 0.02 are not in the projection matrix .*up to $px px (worst image corner)"
      expect_in err "^camproj: warning: k1 = -0.15, k2 = 0.02: the $to export's projection matrix is the pinhole part only and puts points up to $px px (worst image corner)"
    done
    expect_exit 0 "$bin" export "$work/lens.json" --to opencv-yaml
    ! grep -q "k1 = " "$work/err" || fail "opencv-yaml keeps k1 but warned:\n$(cat "$work/err")"
    ;;
  world_origin)
    # Survey-scale coordinates: the projector scene scaled to a 20 m building and moved to UTM-like
    # E, N (float32 spacing 0.5 m at N = 5.6e6). The pixels are unchanged (a uniform scale and a
    # shift of the world), so the fit is the same camera, 20x further away.
    py - "$data/projector/points.csv" "$work/utm.csv" <<'PY'
import sys
rows = [l.strip() for l in open(sys.argv[1]) if l.strip() and not l.startswith("#")]
out = [rows[0]]
for row in rows[1:]:
    X, Y, Z, u, v = map(float, row.split(","))
    out.append("%.17g,%.17g,%.17g,%.17g,%.17g" % (412345.678 + 20 * X, 5612345.678 + 20 * Y, 123.456 + 20 * Z, u, v))
open(sys.argv[2], "w").write("\n".join(out) + "\n")
PY
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080
    ! grep -q "float32" "$work/out" || fail "a unit-scale scene got the float32 note:\n$(cat "$work/out")"
    expect_exit 0 "$bin" fit "$work/utm.csv" --image-size 1920x1080 -o "$work/raw.json"
    ! grep -q world_origin "$work/raw.json" || fail "a fit without --origin wrote a world origin"
    expect_in out "^note: the world coordinates are too large for float32: GL exports would draw points ~[0-9.e+]* px off at the near plane; fit with --origin auto"
    # Without an origin the export warns, with the expected float32 error at the near plane.
    expect_exit 0 "$bin" export "$work/raw.json" --to gl
    expect_in err "^camproj: warning: float32 vertices and view matrix: expected error at the near plane (depth [0-9.]*) [0-9.e+]* px without a world origin, [0-9.e-]* px with --origin auto = "
    expect_in out "^# world origin: none: the view matrix takes world coordinates as they are"
    # --origin auto: the points' centroid rounded per axis to the largest power of ten not above
    # the longest side of their bounding box (docs/conventions.md, section 11), computed here.
    expect_exit 0 "$bin" fit "$work/utm.csv" --image-size 1920x1080 --origin auto -o "$work/cam.json"
    py - "$work/utm.csv" "$work/cam.json" <<'PY' || fail "world_origin is not the rounded centroid"
import json, math, sys
rows = [list(map(float, l.split(",")[:3])) for l in open(sys.argv[1]).read().split("\n")[1:] if l]
extent = max(max(r[a] for r in rows) - min(r[a] for r in rows) for a in range(3))
step = 10 ** math.floor(math.log10(extent))
want = [round(sum(r[a] for r in rows) / len(rows) / step) * step for a in range(3)]
got = json.load(open(sys.argv[2]))["world_origin"]
print(want, got)
sys.exit(0 if got == want else 1)
PY
    origin=$(py -c 'import json,sys; print(",".join("%.17g" % x for x in json.load(open(sys.argv[1]))["world_origin"]))' "$work/cam.json")
    expect_exit 0 "$bin" fit "$work/utm.csv" --image-size 1920x1080 --origin auto
    expect_in out "^note: world origin $origin (--origin auto: the fitted points' centroid, rounded)"
    # The camera is the same: camproj project works in absolute coordinates either way.
    expect_exit 0 "$bin" project "$work/raw.json" "$work/utm.csv"; cp "$work/out" "$work/raw.csv"
    expect_exit 0 "$bin" project "$work/cam.json" "$work/utm.csv"
    cmp -s "$work/out" "$work/raw.csv" || fail "camproj project differs with a world origin"
    # The gl export: header, no warning, and the matrices take point_in_world - origin: the
    # projection * view of (X - origin), in double, lands on camproj project's pixels. Tolerance
    # 1e-6 px: the pose's t (~5.6e6 m) holds the camera centre only to its double spacing
    # (~1e-9 m), which C - origin keeps: ~f 1e-9 / depth ~ 1e-7 px (measured 7e-8 px).
    expect_exit 0 "$bin" export "$work/cam.json" --to gl
    ! grep -q "warning: float32" "$work/err" || fail "warned with a world origin:\n$(cat "$work/err")"
    expect_in err "^camproj: note: float32 vertices and view matrix: expected error at the near plane .* px with the world origin $origin"
    expect_in out "^# camproj GL export: projection = clip_from_gl_eye, view = gl_eye_from_origin_world"
    expect_in out "^# world origin (${origin//,/, }): the view matrix is gl_eye_from_origin_world: give vertices as point_in_world - "
    py - "$work/out" "$work/raw.csv" "$origin" <<'PY' || fail "the origin-relative GL matrices miss camproj project's pixels"
import sys
import numpy as np
m = {l.split()[0]: np.array(list(map(float, l.split()[1:]))).reshape(4, 4).T
     for l in open(sys.argv[1]) if l.split()[0] in ("projection", "view")}
origin = np.array(list(map(float, sys.argv[3].split(","))))
worst = 0
for line in open(sys.argv[2]).read().split("\n")[1:]:
    if not line: continue
    _, X, Y, Z, u, v, _ = line.split(",")
    p = np.append(np.array([float(X), float(Y), float(Z)]) - origin, 1.0)
    clip = m["projection"] @ m["view"] @ p
    ndc = clip[:3] / clip[3]
    gu, gv = (ndc[0] + 1) / 2 * 1920 - 0.5, 1080 - (ndc[1] + 1) / 2 * 1080 - 0.5
    worst = max(worst, np.hypot(gu - float(u), gv - float(v)))
print("worst", worst)
sys.exit(0 if worst < 1e-6 else 1)
PY
    # --origin none overrides the file's: world coordinates again, and the warning.
    expect_exit 0 "$bin" export "$work/cam.json" --to gl --origin none
    expect_in out "^# world origin: none"
    expect_in err "^camproj: warning: float32 vertices"
    # --origin auto at export: the camera centre rounded to a power of ten not above near.
    expect_exit 0 "$bin" export "$work/raw.json" --to gl --origin auto
    expect_in out "^# world origin ("
    ! grep -q "warning: float32" "$work/err" || fail "warned with --origin auto:\n$(cat "$work/err")"
    # glm, three and json carry it too.
    expect_exit 0 "$bin" export "$work/cam.json" --to glm
    expect_in out "^const glm::dvec3 world_origin("
    expect_in out "^// world origin ("
    expect_exit 0 "$bin" export "$work/cam.json" --to three
    expect_in out '"world_origin": \['
    expect_in out "give vertices as point_in_world - "
    expect_exit 0 "$bin" export "$work/raw.json" --to json --origin 412000,5612000,100
    py -c 'import json,sys; sys.exit(json.load(open(sys.argv[1]))["world_origin"] != [412000, 5612000, 100])' "$work/out" \
      || fail "json export lacks the --origin"
    # Bad values: exit 1 naming the option, nothing on stdout, no camera file.
    expect_exit 1 "$bin" export "$work/cam.json" --to gl --origin 1,2
    expect_in err "--origin (auto, none or X,Y,Z): expected 3 comma-separated numbers, got 2"
    [[ ! -s "$work/out" ]] || fail "a refused export printed:\n$(cat "$work/out")"
    expect_exit 1 "$bin" export "$work/cam.json" --to gl --origin middle
    expect_in err '"middle" is not a finite number'
    expect_exit 1 "$bin" export "$work/cam.json" --to gl --origin 1.7e308,-1.7e308,1.7e308
    expect_in err "--origin: 1.7e308,-1.7e308,1.7e308 is too far from the camera"
    [[ ! -s "$work/out" ]] || fail "a refused export printed:\n$(cat "$work/out")"
    expect_exit 1 "$bin" fit "$work/utm.csv" --image-size 1920x1080 --origin 1,2,nan -o "$work/bad.json"
    expect_in err "--origin (auto or X,Y,Z)"
    [[ ! -e "$work/bad.json" ]] || fail "a refused fit wrote a camera file"
    # A camera file's bad world_origin names the key.
    py -c 'import json,sys; c = json.load(open(sys.argv[1])); c["world_origin"] = [1, 2]; json.dump(c, open(sys.argv[2], "w"))' "$work/cam.json" "$work/bad_origin.json"
    expect_exit 2 "$bin" export "$work/bad_origin.json" --to gl
    expect_in err "world_origin: expected an array of 3 numbers"
    ;;
  project_points)
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$data/projector/points.csv"
    expect_in out "^id,X,Y,Z,u,v,depth"
    [[ $(wc -l <"$work/out") -eq 21 ]] || fail "expected 20 rows"
    printf 'X,Y,Z\n0,0,0\n' >"$work/xyz.csv"
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$work/xyz.csv"
    # Its own output reads back (u, v are not read: a point behind the camera has them empty,
    # which was "expected a number").
    py - "$data/projector/truth.json" "$work/ids.csv" <<'PY'
import json, sys
pose = json.load(open(sys.argv[1]))["cam_from_world"]
R, t = pose["R"], pose["t"]
eye = [-sum(R[r][c] * t[r] for r in range(3)) for c in range(3)]
with open(sys.argv[2], "w") as f:  # the origin, and a point as far behind the eye
    f.write("id,X,Y,Z\nfront,0,0,0\nbehind,%r,%r,%r\n" % tuple(2 * e for e in eye))
PY
    "$bin" project "$data/projector/truth.json" "$work/ids.csv" >"$work/projected.csv" || fail "project"
    grep -q '^behind,.*,,,' "$work/projected.csv" || fail "the point behind has pixels: $(cat "$work/projected.csv")"
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$work/projected.csv"
    cmp -s "$work/out" "$work/projected.csv" || fail "project of its own output differs"
    ;;
  convert_round_trip)
    expect_exit 0 "$bin" convert --intrinsics 1000,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum
    expect_in out "left -0.096"
    # A principal point on the bottom row's centre puts the frustum's bottom at 0 ("-0" before).
    expect_exit 0 "$bin" convert --intrinsics 1000,1000,959.5,1079.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum
    expect_in out "^bottom 0$"
    expect_exit 0 "$bin" convert --frustum -0.096,0.096,-0.054,0.054,0.1,100 --image-size 1920x1080 --to intrinsics
    expect_in out "fx 1000"
    expect_in out "cx 959.5"
    expect_exit 2 "$bin" convert --intrinsics 1000,1000,900,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to perspective
    expect_in err "off-axis"
    expect_exit 1 "$bin" convert --intrinsics 1000,1000 --image-size 1920x1080 --near 0.1 --far 100 --to frustum
    ;;
  synth_reproducible)
    expect_exit 0 "$bin" synth --seed 5 --points 12 --noise 0.5 -o "$work/a.csv" --truth "$work/a.json"
    expect_exit 0 "$bin" synth --seed 5 --points 12 --noise 0.5 -o "$work/b.csv" --truth "$work/b.json"
    cmp -s "$work/a.csv" "$work/b.csv" || fail "same seed, different points"
    cmp -s "$work/a.json" "$work/b.json" || fail "same seed, different truth"
    # The CSV's first line is the command that makes the scene again, every option spelled out
    # (it named --seed and --points only).
    expect_exit 0 "$bin" synth --seed 5 --points 12 --noise 0.5 --object box --fovy 50 \
      --principal-point-offset 0,0.5 --image-size 1280x720 --aspect 1.01 -o "$work/c.csv" --truth "$work/c.json"
    command=$(head -1 "$work/c.csv" | sed -e 's/^# camproj //' -e 's/ (pixels: OpenCV convention)$//')
    # shellcheck disable=SC2086
    expect_exit 0 "$bin" $command -o "$work/d.csv" --truth "$work/d.json"
    cmp -s "$work/c.csv" "$work/d.csv" || fail "the recorded command made another scene: $command"
    cmp -s "$work/c.json" "$work/d.json" || fail "the recorded command made another truth: $command"
    # --planar is --object plane: beside another --object it was dropped without a word.
    expect_exit 1 "$bin" synth --object box --planar -o "$work/e.csv" --truth "$work/e.json"
    expect_in err "excludes"
    ;;
  overlay_png)
    expect_exit 0 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/o.png"
    [[ $(head -c 8 "$work/o.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]] || fail "not a PNG"
    expect_exit 2 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" "$work/missing.jpg" -o "$work/p.png"
    [[ ! -e "$work/p.png" ]] || fail "partial output"
    ;;
  overlay_which_click)
    # Two clicks moved by 180 px and 120 px: the fit leaves them out, and the overlay names them
    # (kind outlier in the label table, how far off), ids for every point, a JPEG for .jpg.
    py -c "
import sys
lines = open(sys.argv[1]).read().splitlines()
out, header, row = [], None, 0
for line in lines:
    if line.startswith('#') or header is None:
        if not line.startswith('#'): header = line.split(',')
        out.append(line); continue
    f = line.split(','); row += 1
    if row == 3: f[header.index('u')] = str(float(f[header.index('u')]) + 180)
    if row == 7: f[header.index('v')] = str(float(f[header.index('v')]) - 120)
    out.append(','.join(f))
open(sys.argv[2], 'w').write('\\n'.join(out) + '\\n')" "$data/projector/points.csv" "$work/mis.csv"
    expect_exit 0 "$bin" fit "$work/mis.csv" --image-size 1920x1080 -o "$work/cam.json"
    expect_exit 0 "$bin" overlay "$work/cam.json" "$work/mis.csv" -o "$work/o.jpg" --labels "$work/labels.csv"
    expect_in out "18 points, 2 outliers; residuals x "
    [[ $(head -c 3 "$work/o.jpg" | od -An -tx1 | tr -d ' \n') == ffd8ff ]] || fail "not a JPEG"
    [[ $(grep -c ',outlier,' "$work/labels.csv") -eq 2 ]] || fail "outliers not labelled: $(cat "$work/labels.csv")"
    grep -q '^3,outlier,' "$work/labels.csv" || fail "point 3 not an outlier"
    grep -q '^7,outlier,' "$work/labels.csv" || fail "point 7 not an outlier"
    [[ $(tail -n +2 "$work/labels.csv" | wc -l) -eq 20 ]] || fail "not one label per point"
    # The label table is an output too: it may not replace an input.
    expect_exit 2 "$bin" overlay "$work/cam.json" "$work/mis.csv" -o "$work/o2.png" --labels "$work/mis.csv"
    [[ ! -e "$work/o2.png" ]] || fail "wrote the picture although the labels would replace an input"
    ;;
  fit_report)
    # camproj fit --report: an SVG (well-formed XML) with a bar per point, an arrow per kept point,
    # the models tried; .html wraps it with the summary; other extensions refused before fitting.
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --report "$work/r.svg"
    py -c "import sys, xml.dom.minidom as m; d = m.parse(sys.argv[1]); n = len(d.getElementsByTagName('rect')); sys.exit(0 if n >= 21 else 1)" "$work/r.svg" \
      || fail "the report is not well-formed SVG with a bar per point"
    [[ $(grep -c "marker-end='url(#head)'" "$work/r.svg") -eq 20 ]] || fail "not an arrow per point"
    expect_in_file() { grep -q -- "$2" "$1" || fail "$1 lacks '$2'"; }
    expect_in_file "$work/r.svg" "Models tried, in order: BIC"
    expect_in_file "$work/r.svg" "pose+focal+principal-point"
    expect_in_file "$work/r.svg" "Residuals over the image (1920x1080 px): arrows x "
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --report "$work/r.html"
    expect_in_file "$work/r.html" "<svg"
    expect_in_file "$work/r.html" "model: pose+focal+principal-point"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 --report "$work/r.png"
    expect_in err "a report is .svg or .html"
    # Exact points: no arrows of rounding magnified 1e15 times, ticks that differ (all "0.00"
    # before session 43). Ids cut by character and a Latin-1 byte shown as U+FFFD: the SVG stays
    # XML (a 12-byte cut split a u-umlaut); a pixel observed outside the image is an arrow at
    # the border pointing at it (drawn outside the picture before).
    expect_exit 0 "$bin" synth --seed 3 --points 12 --noise 0 -o "$work/exact.csv" --truth "$work/exact_truth.json"
    expect_exit 0 "$bin" fit "$work/exact.csv" --image-size 1920x1080 --report "$work/exact.svg"
    expect_in_file "$work/exact.svg" "all below 1e-06 px (rounding), no arrows"
    expect_in_file "$work/exact.svg" "text-anchor='end'>0.0002<"
    py - "$work/exact.csv" "$work/ids.csv" <<'PY'
import sys
rows = [l.strip().split(',') for l in open(sys.argv[1]) if not l.startswith('#')][1:]
with open(sys.argv[2], 'wb') as out:
    out.write(b'id,X,Y,Z,u,v\n')
    for i, r in enumerate(rows):
        if i == 2:
            r[3:5] = ['-300', '500']
        name = {0: b'corner_nord\xc3\xbc1', 1: b'S\xfcd'}.get(i, b'p%d' % i)
        out.write(name + b',' + ','.join(r).encode() + b'\n')
PY
    expect_exit 0 "$bin" fit "$work/ids.csv" --image-size 1920x1080 --report "$work/ids.svg"
    py -c "import sys, xml.dom.minidom as m; m.parse(sys.argv[1])" "$work/ids.svg" \
      || fail "the report with non-ASCII ids is not well-formed XML"
    expect_in_file "$work/ids.svg" $'corner_nord\xc3\xbc<'
    expect_in_file "$work/ids.svg" "p2: observed at (-300, 500), outside the image"
    expect_in_file "$work/ids.svg" "p2 (outside)"
    expect_exit 1 "$bin" fit "$data/projector/points.csv" "$data/plane/points.csv" --image-size 1920x1080 -o "$work/batch" --report "$work/b.svg"
    expect_in err "--report is for one points file"
    ;;
  view_page)
    # camproj view: one self-contained page (nothing fetched: no src= or href= to anything), the
    # camera alone or with points, a photo and a model; bad inputs named, nothing written.
    expect_exit 0 "$bin" view "$data/projector/truth.json" -o "$work/camera_only.html"
    expect_in out "wrote $work/camera_only.html (0 points"
    # An id or a title that reads like one of the template's keys stays text: every key is
    # filled in one pass over the template (an id "@CAMPROJ_PAGE_SCRIPT@" took the page script's
    # place, leaving the page without it, before session 37).
    printf 'id,X,Y,Z,u,v\n@CAMPROJ_PAGE_SCRIPT@,0.1,0.1,2,550,450\n' >"$work/key_id.csv"
    expect_exit 0 "$bin" view "$data/projector/truth.json" "$work/key_id.csv" -o "$work/keys.html" \
        --title '@CAMPROJ_DATA@'
    grep -q '<title>@CAMPROJ_DATA@</title>' "$work/keys.html" || fail "the title is not kept as text"
    grep -q '"id":"@CAMPROJ_PAGE_SCRIPT@"' "$work/keys.html" || fail "the id is not kept as text"
    grep -q '<script type="text/plain" id="page-script">[A-Za-z0-9+/=]\{1000,\}</script>' \
        "$work/keys.html" || fail "the page script is not in the page"
    expect_exit 0 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/photo.jpg"
    printf 'o box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf -4/1 -3/2 -2/3\n' >"$work/box.obj"
    expect_exit 0 "$bin" view "$data/projector/truth.json" "$data/projector/points.csv" \
      --image "$work/photo.jpg" --mesh "$work/box.obj" -o "$work/v.html"
    expect_in out "(20 points, 3 triangles"
    grep -q '<pre id="camproj-test-result">' "$work/v.html" || fail "no test element"
    grep -q '"data_url":"data:image/jpeg;base64,' "$work/v.html" || fail "photo not inlined"
    if grep -Eiq '<(script|img|link|iframe)[^>]*(src|href)=' "$work/v.html"; then
      fail "the page refers to another file"
    fi
    # Bad model: the file, the line, what is wrong; the old page stays.
    cp "$work/v.html" "$work/v.orig.html"
    printf 'v 0 0 0\nv 1 0 x\n' >"$work/bad.obj"
    expect_exit 2 "$bin" view "$data/projector/truth.json" --mesh "$work/bad.obj" -o "$work/v.html"
    expect_in err "bad.obj: line 2: vertex coordinate 3 is not a finite number"
    printf 'v 0 0 0\nv 1 0 0\nf 1 2 3\n' >"$work/bad.obj"
    expect_exit 2 "$bin" view "$data/projector/truth.json" --mesh "$work/bad.obj" -o "$work/v.html"
    expect_in err "bad.obj: line 3: face vertex 3 refers to vertex 3 but 2 are defined so far"
    cmp -s "$work/v.html" "$work/v.orig.html" || fail "a failed view replaced the page"
    # A photo of another size; an output that is an input; not .html.
    expect_exit 0 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/photo.png"
    py -c "import json,sys; c=json.load(open(sys.argv[1])); c['image_size']=[960,540]; json.dump(c, open(sys.argv[2],'w'))" \
      "$data/projector/truth.json" "$work/small.json"
    expect_exit 2 "$bin" view "$work/small.json" --image "$work/photo.png" -o "$work/s.html"
    expect_in err "photo.png: image is 1920x1080 but the camera's image size is 960x540"
    [[ ! -e "$work/s.html" ]] || fail "wrote a page for a photo of the wrong size"
    # A JPEG with an EXIF orientation is taken as displayed, by overlay and view alike: turned a
    # quarter (6) for a portrait camera, half round (3) for the landscape one. The page embeds it
    # turned upright, without the orientation, its pixels OpenCV's turned decode (to JPEG's
    # re-encoding); a stored size that fits only unturned is refused naming the orientation.
    # (Before session 44 view refused the quarter turn by its stored size and embedded the half
    # turn as stored, which the page's 3D texture need not turn.)
    py - "$work/photo.jpg" "$data/projector/truth.json" "$work" <<'PY'
import json, struct, sys
def with_orientation(src, dst, orientation, big_endian):
    data = open(src, "rb").read()
    e = ">" if big_endian else "<"
    tiff = (b"MM" if big_endian else b"II") + struct.pack(e + "HI", 42, 8) + struct.pack(e + "H", 1)
    tiff += struct.pack(e + "HHI", 0x0112, 3, 1) + struct.pack(e + "HH", orientation, 0) + struct.pack(e + "I", 0)
    payload = b"Exif\x00\x00" + tiff
    open(dst, "wb").write(data[:2] + b"\xff\xe1" + struct.pack(">H", len(payload) + 2) + payload + data[2:])
with_orientation(sys.argv[1], sys.argv[3] + "/turned6.jpg", 6, False)
with_orientation(sys.argv[1], sys.argv[3] + "/turned3.jpg", 3, True)
c = json.load(open(sys.argv[2]))
for k in ("gl", "look_at"): del c[k]
c["frustum"] = {"near": c["frustum"]["near"], "far": c["frustum"]["far"]}
c["image_size"] = [1080, 1920]
c["intrinsics"].update(cx=539.5, cy=959.5)
json.dump(c, open(sys.argv[3] + "/portrait.json", "w"))
PY
    expect_exit 0 "$bin" overlay "$work/portrait.json" "$data/projector/points.csv" "$work/turned6.jpg" -o "$work/o6.png"
    expect_exit 0 "$bin" view "$work/portrait.json" --image "$work/turned6.jpg" -o "$work/v6.html"
    expect_exit 0 "$bin" view "$data/projector/truth.json" --image "$work/turned3.jpg" -o "$work/v3.html"
    expect_exit 2 "$bin" view "$data/projector/truth.json" --image "$work/turned6.jpg" -o "$work/s.html"
    expect_in err "turned6.jpg: image is 1080x1920 as displayed (its EXIF orientation 6 turns its stored 1920x1080) but the camera's image size is 1920x1080"
    expect_exit 2 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" "$work/turned6.jpg" -o "$work/s.png"
    expect_in err "turned6.jpg: image is 1080x1920 as displayed (its EXIF orientation 6"
    py - "$work" <<'PY' || fail "the page's photo is not the JPEG as displayed"
import base64, json, re, sys
import cv2, numpy as np
for page, photo, size in (("v6.html", "turned6.jpg", (1920, 1080)), ("v3.html", "turned3.jpg", (1080, 1920))):
    text = open(sys.argv[1] + "/" + page).read()
    data = json.loads(re.search(r'<script type="application/json" id="camproj-data">(.*?)</script>', text, re.S).group(1))
    embedded = base64.b64decode(data["image"]["data_url"].split(",", 1)[1])
    assert b"Exif" not in embedded[:4096], page
    upright = cv2.imdecode(np.frombuffer(embedded, np.uint8), cv2.IMREAD_COLOR)
    shown = cv2.imread(sys.argv[1] + "/" + photo, cv2.IMREAD_COLOR)  # OpenCV applies the orientation
    assert upright.shape[:2] == shown.shape[:2] == size, (page, upright.shape, shown.shape)
    # Re-encoded at quality 95: a mean difference of ~0.1 grey level (measured 0.08); the same
    # photo turned half round differs by ~6.
    diff = np.abs(upright.astype(float) - shown.astype(float)).mean()
    print(page, diff)
    assert diff < 1, diff
PY
    # A photo cut short: refused, as overlay refuses it, not embedded with its end missing.
    head -c 20000 "$work/photo.png" >"$work/cut.png"
    expect_exit 2 "$bin" view "$data/projector/truth.json" --image "$work/cut.png" -o "$work/s.html"
    expect_in err "cut.png: the PNG ends before its IEND chunk: the file is truncated"
    [[ ! -e "$work/s.html" ]] || fail "wrote a page for a truncated photo"
    # The camera file's fit record goes into the page's HTML: a field of another type than camproj
    # fit writes is left out with a note (a num_points of '<img onerror=...>' ran as script, and
    # a left_out of "none" stopped the page's script, before session 43).
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/fitted.json"
    py -c "import json,sys; c=json.load(open(sys.argv[1])); c['fit']['num_points']='<img src=x onerror=alert(1)>'; c['fit']['left_out']='none'; json.dump(c, open(sys.argv[2],'w'))" \
      "$work/fitted.json" "$work/xss.json"
    expect_exit 0 "$bin" view "$work/xss.json" "$data/projector/points.csv" -o "$work/xss.html"
    if grep -q "onerror" "$work/xss.html"; then fail "the page holds the camera file's markup"; fi
    grep -q "the camera file's fit.left_out is not as camproj fit writes it" "$work/xss.html" \
      || fail "no note for the mistyped fit.left_out"
    grep -q '"rms_px":' "$work/xss.html" || fail "the well-typed fit fields are not in the page"
    # A lens: the image plane is drawn through it, each vertex on its pixel's ray (the photo's
    # pixel where the ray through it meets the plane), and the note names the lens's terms; an
    # orthographic camera's rays start on the near plane, along the view axis (they started
    # behind the camera, from the eye's side, before session 44).
    py - "$data/projector/truth.json" "$work" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
for k in ("gl", "look_at"): del c[k]
c["frustum"] = {"near": c["frustum"]["near"], "far": c["frustum"]["far"]}
c["intrinsics"].update(k1=-0.15, k2=0.02)
json.dump(c, open(sys.argv[2] + "/lens.json", "w"))
c["projection"] = "orthographic"
c["intrinsics"] = dict(fx=800.0, fy=800.0, cx=959.5, cy=539.5, skew=0.0)
c["frustum"] = {"near": 0.5, "far": 3.0}
json.dump(c, open(sys.argv[2] + "/ortho.json", "w"))
PY
    expect_exit 0 "$bin" view "$work/lens.json" "$data/projector/points.csv" -o "$work/lens.html"
    expect_exit 0 "$bin" view "$work/ortho.json" "$data/projector/points.csv" -o "$work/ortho.html"
    py -c "import json, sys; c = json.load(open(sys.argv[1])); c['intrinsics'].update(k1=-0.5, k2=0.0); json.dump(c, open(sys.argv[2], 'w'))" \
      "$work/lens.json" "$work/fold.json"
    expect_exit 0 "$bin" view "$work/fold.json" -o "$work/fold.html"
    py - "$work/lens.json" "$work/lens.html" "$work/ortho.json" "$work/ortho.html" "$work/fold.html" <<'PY' || fail "the page's image plane or rays are not the camera's"
import json, re, sys
def page_data(path):
    text = open(path).read()
    m = re.search(r'<script type="application/json" id="camproj-data">(.*?)</script>', text, re.S)
    return json.loads(m.group(1))
def cam_point(c, X):
    R, t = c["cam_from_world"]["R"], c["cam_from_world"]["t"]
    return [sum(R[i][k] * X[k] for k in range(3)) + t[i] for i in range(3)]
# Each vertex at the image plane's depth, on its pixel's ray: projected with the lens (k1, k2 as
# OpenCV's model) onto the pixel its texture coordinate names, to double rounding at 2000 px.
c, d = json.load(open(sys.argv[1])), page_data(sys.argv[2])
K, (W, H) = c["intrinsics"], c["image_size"]
o, img, depth = d["page_origin_in_world"], d["frustum"]["image_plane"], d["frustum"]["image_depth"]
assert img["through_lens"] and len(img["triangles"]) > 2, "the lens's image plane is not a grid"
worst = 0.0
for p, (s, tv) in zip(img["positions_in_page"], img["uv"]):
    x = cam_point(c, [p[k] + o[k] for k in range(3)])
    assert abs(x[2] - depth) <= 1e-9 * depth, (x[2], depth)
    xn, yn = x[0] / x[2], x[1] / x[2]
    r2 = xn * xn + yn * yn
    f = 1 + K["k1"] * r2 + K["k2"] * r2 * r2
    u, v = K["fx"] * xn * f + K["cx"], K["fy"] * yn * f + K["cy"]
    worst = max(worst, abs(u - (-0.5 + s * W)), abs(v - (-0.5 + (1 - tv) * H)))
assert worst <= 1e-6, worst
assert any("the lens (k1 = -0.15, k2 = 0.02)" in n for n in d["notes"]), d["notes"]
# Its border: one closed loop round the grid (first vertex repeated at its end).
(loop,) = img["outline_in_page"]
cols = sum(1 for s, t in img["uv"] if t == 1.0) - 1
rows = sum(1 for s, t in img["uv"] if s == 0.0) - 1
assert loop[0] == loop[-1] and len(loop) == 2 * (cols + rows) + 1, (len(loop), cols, rows)
assert img["top_edge_in_page"] == loop[:cols + 1]
# A lens that folds inside the image (k1 = -0.5: only the bottom edge, nearest the principal
# point, has rays): the border's runs stop where it folds, and none bridges the gap with a chord
# (one of 2.24 units closed the bottom edge into a loop before session 44).
d = page_data(sys.argv[5])
runs = d["frustum"]["image_plane"]["outline_in_page"]
lengths = [sum((a[k] - b[k]) ** 2 for k in range(3)) ** 0.5 for run in runs for a, b in zip(run, run[1:])]
assert runs and sum(map(len, runs)) < 2 * (cols + rows), [len(r) for r in runs]
assert max(lengths) < 5 * sorted(lengths)[len(lengths) // 2], (max(lengths), sorted(lengths)[len(lengths) // 2])
c, d = json.load(open(sys.argv[3])), page_data(sys.argv[4])
o, rays = d["page_origin_in_world"], 0
for p in d["points"]:
    a = cam_point(c, [p["ray_start_in_page"][k] + o[k] for k in range(3)])
    b = cam_point(c, [p["ray_end_in_page"][k] + o[k] for k in range(3)])
    assert abs(a[2] - c["frustum"]["near"]) <= 1e-9, a
    assert abs(a[0] - b[0]) <= 1e-9 and abs(a[1] - b[1]) <= 1e-9, (a, b)
    rays += 1
assert rays == 20 and not d["frustum"]["image_plane"]["through_lens"]
PY
    # A camera fitted in the corner convention beside points whose convention is left to the
    # default: overlay, view and project say the two differ; given either way, nothing is said.
    py - "$data/projector/points.csv" "$work/corner.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#")))
with open(sys.argv[2], "w") as f:
    f.write("X,Y,Z,u,v\n")
    for r in rows:
        f.write(f"{r['X']},{r['Y']},{r['Z']},{float(r['u']) + 0.5!r},{float(r['v']) + 0.5!r}\n")
PY
    expect_exit 0 "$bin" fit "$work/corner.csv" --image-size 1920x1080 --pixel-origin corner -o "$work/corner.json"
    note="corner.json states its cx, cy in the corner convention (its pixel_origin), but"
    expect_exit 0 "$bin" view "$work/corner.json" "$work/corner.csv" -o "$work/corner.html"
    expect_in err "^camproj: note: .*$note .*corner.csv's pixels are read in the center convention (--pixel-origin's default; the two differ by 0.5 px along u and v): give --pixel-origin corner to use the camera file's"
    expect_exit 0 "$bin" overlay "$work/corner.json" "$work/corner.csv" -o "$work/corner.png"
    expect_in err "^camproj: note: .*$note .*corner.csv's pixels are read in the center convention"
    expect_exit 0 "$bin" project "$work/corner.json" "$work/corner.csv"
    expect_in err "^camproj: note: .*$note the pixels are printed in the center convention"
    for origin in corner center; do
      expect_exit 0 "$bin" view "$work/corner.json" "$work/corner.csv" -o "$work/corner.html" --pixel-origin $origin
      expect_not_in err "note"
      expect_exit 0 "$bin" overlay "$work/corner.json" "$work/corner.csv" -o "$work/corner.png" --pixel-origin $origin
      expect_not_in err "note"
      expect_exit 0 "$bin" project "$work/corner.json" "$work/corner.csv" --pixel-origin $origin
      expect_not_in err "note"
    done
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$work/corner.csv"
    expect_not_in err "note"
    cp "$data/projector/truth.json" "$work/cam.html"
    expect_exit 2 "$bin" view "$work/cam.html" -o "$work/cam.html"
    expect_exit 1 "$bin" view "$data/projector/truth.json" -o "$work/v.png"
    expect_in err "must end in .html"
    ;;
  deep_json_refused)
    # 100000 nested arrays inside a checked key (200 KB, under the 1 MiB limit): main crashed in
    # nlohmann's recursive dump() building the message (SIGSEGV, exit 139).
    py -c "n=100000; print('{\"image_size\": ' + '['*n + ']'*n + '}')" >"$work/deep.json"
    for cmd in "export $work/deep.json" "project $work/deep.json $data/projector/points.csv" \
               "overlay $work/deep.json $data/projector/points.csv -o $work/o.png" \
               "fit $data/projector/points.csv --image-size 1920x1080 --intrinsics $work/deep.json"; do
      expect_exit 2 "$bin" $cmd
      expect_in err "deep.json: line 1: arrays and objects nest deeper than 32 levels"
    done
    # Just under the reader's 1 MiB limit, in objects, after a valid start.
    py -c "n=174000; print('{\"image_size\": [640, 480], \"x\": ' + '{\"a\":'*n + '1' + '}'*n + '}')" >"$work/deep2.json"
    expect_exit 2 "$bin" export "$work/deep2.json"
    expect_in err "nest deeper"
    # The reader's other bounds (docs/reliability.md): 1 MiB, and image_size up to 10^6.
    { printf '{"image_size": [640, 480]'; head -c 1100000 /dev/zero | tr '\0' ' '; printf '}'; } >"$work/big.json"
    expect_exit 2 "$bin" export "$work/big.json"
    expect_in err "big.json: larger than 1048576 bytes"
    printf '{"image_size": [1000001, 480]}' >"$work/wide.json"
    expect_exit 2 "$bin" export "$work/wide.json"
    expect_in err "wide.json: image_size: expected two positive integers"
    # Wrong values are described, not quoted back.
    printf '{"image_size": [640, [[1]]]}' >"$work/typed.json"
    expect_exit 2 "$bin" export "$work/typed.json"
    expect_in err 'image_size\[1\]: expected a number, got an array of 1 elements'
    ;;
  output_is_input_refused)
    cp "$data/projector/points.csv" "$work/p.csv"
    expect_exit 2 "$bin" fit "$work/p.csv" --image-size 1920x1080 -o "$work/p.csv"
    expect_in err "p.csv: the output is the input"
    cmp -s "$data/projector/points.csv" "$work/p.csv" || fail "fit replaced its input"
    ln -s p.csv "$work/link.json"
    ln "$work/p.csv" "$work/hard.json"
    for out in link.json hard.json; do
      expect_exit 2 "$bin" fit "$work/p.csv" --image-size 1920x1080 -o "$work/$out"
      expect_in err "the output is the input"
    done
    cmp -s "$data/projector/points.csv" "$work/p.csv" || fail "fit replaced its input through a link"
    cp "$data/projector/truth.json" "$work/cam.json"
    expect_exit 2 "$bin" fit "$work/p.csv" --image-size 1920x1080 --intrinsics "$work/cam.json" -o "$work/cam.json"
    cmp -s "$data/projector/truth.json" "$work/cam.json" || fail "fit replaced its --intrinsics file"
    # overlay: the photo it draws on, and its camera and points files.
    expect_exit 0 "$bin" overlay "$work/cam.json" "$work/p.csv" -o "$work/photo.png"
    cp "$work/photo.png" "$work/photo.orig.png"
    for out in photo.png cam.json p.csv; do
      expect_exit 2 "$bin" overlay "$work/cam.json" "$work/p.csv" "$work/photo.png" -o "$work/$out"
      expect_in err "the output is the input"
    done
    cmp -s "$work/photo.png" "$work/photo.orig.png" || fail "overlay replaced its photo"
    cmp -s "$data/projector/truth.json" "$work/cam.json" || fail "overlay replaced its camera"
    ;;
  batch_name_collision_refused)
    mkdir -p "$work/a" "$work/b"
    cp "$data/projector/points.csv" "$work/a/cam.csv"
    cp "$data/synthetic/points.csv" "$work/b/cam.csv"
    expect_exit 1 "$bin" fit "$work/a/cam.csv" "$work/b/cam.csv" --image-size 1920x1080 -o "$work/cams"
    expect_in err "inputs .*a/cam.csv and .*b/cam.csv would both write .*cams/cam.json"
    [[ ! -e "$work/cams" ]] || fail "refused up front, yet something was written"
    ;;
  batch_json_lines)
    mkdir -p "$work/in"
    cp "$data/projector/points.csv" "$work/in/projector.csv"
    printf 'X,Y,Z,u,v\n1,2,x,4,5\n' >"$work/in/broken.csv"
    expect_exit 2 "$bin" fit "$work/in" --image-size 1920x1080 -o "$work/cams" --json --jobs 2
    [[ $(wc -l <"$work/out") -eq 2 ]] || fail "expected 2 JSON lines:\n$(cat "$work/out")"
    py -c '
import json, sys
rows = [json.loads(line) for line in open(sys.argv[1])]
assert rows[0]["file"].endswith("broken.csv") and rows[0]["status"] == "bad input" and rows[0]["exit_code"] == 2 and rows[0]["camera_file"] is None, rows[0]
assert rows[1]["status"] == "ok" and rows[1]["camera_file"].endswith("projector.json"), rows[1]
json.load(open(rows[1]["camera_file"]))
' "$work/out" || fail "bad JSON lines:\n$(cat "$work/out")"
    expect_in err "1 of 2 fitted"
    ;;
  no_stray_temporary_after_kill)
    # A signal in the middle of a batch, at several moments after the first camera file appeared:
    # every camera file present is whole JSON and nothing else is in the folder (main left 1-2
    # *.tmp.* files per SIGKILL). 20 fits of 3000 points take ~0.5 s on 2 threads in Release.
    "$bin" synth --seed 2 --points 3000 -o "$work/big.csv" --truth "$work/truth.json" >/dev/null || fail "synth"
    mkdir -p "$work/in"
    for i in $(seq 1 20); do cp "$work/big.csv" "$work/in/s$i.csv"; done
    # kill_batch SIGNAL DELAY [ENV...]: starts the batch, waits (<= 20 s) for its first camera
    # file, sleeps DELAY, sends SIGNAL, then checks the folder.
    kill_batch() {
      local signal=$1 delay=$2; shift 2
      rm -rf "$work/cams"
      env "$@" "$bin" fit "$work/in" --image-size 1920x1080 -o "$work/cams" --jobs 2 >/dev/null 2>&1 &
      local pid=$! waited=0
      until compgen -G "$work/cams/*.json" >/dev/null || ((waited++ > 2000)); do sleep 0.01; done
      sleep "$delay"
      kill "-$signal" "$pid" 2>/dev/null
      wait "$pid" 2>/dev/null
      local stray
      stray=$(ls -A "$work/cams" | grep -v '^s[0-9]*\.json$')
      [[ -z "$stray" ]] || fail "left after SIG$signal at +${delay}s ($*): $stray"
      for f in "$work/cams"/*.json; do
        py -c 'import json, sys; json.load(open(sys.argv[1]))' "$f" || fail "$f is not whole JSON"
      done
    }
    for delay in 0 0.1; do kill_batch KILL "$delay"; done
    # A temporary left by a kill over an hour ago is swept by the next write there; a recent one
    # (maybe another camproj's write in progress) is left alone.
    touch -d '2 hours ago' "$work/cams/.camproj-Stale1.tmp"
    touch "$work/cams/.camproj-Fresh1.tmp"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/cams/one.json"
    [[ ! -e "$work/cams/.camproj-Stale1.tmp" ]] || fail "a stale temporary was not swept"
    [[ -e "$work/cams/.camproj-Fresh1.tmp" ]] || fail "a recent temporary was removed"
    # Without O_TMPFILE (forced): the named temporary is removed on SIGTERM and SIGHUP (SIGINT has
    # the same handler, but a background job of a script ignores it).
    kill_batch TERM 0 CAMPROJ_TEST_NO_TMPFILE=1
    kill_batch HUP 0.05 CAMPROJ_TEST_NO_TMPFILE=1
    ;;
  outputs_distinct_all_or_nothing)
    # Two outputs of one command naming one file are refused before any work (the second write
    # destroyed the first, exit 0, before session 37); where the second cannot be written, the
    # first is not written either (it was left behind with exit 2).
    boards="$data/real/opencv_chessboard"
    points="$data/projector/points.csv"
    cd "$work" || fail "cd"
    expect_exit 1 "$bin" synth -o same.json --truth ./same.json
    expect_in err "usage: -o and --truth both name ./same.json: give each output its own path"
    expect_exit 1 "$bin" calibrate "$boards"/left0[1-5].csv --image-size 640x480 -o c.json --poses c.json
    expect_in err "usage: -o and --poses both name c.json"
    expect_exit 1 "$bin" fit "$points" --image-size 1920x1080 -o r.svg --report sub/../r.svg
    expect_in err "usage: -o and --report both name sub/../r.svg"
    expect_exit 0 "$bin" fit "$points" --image-size 1920x1080 -o cam.json
    expect_exit 1 "$bin" overlay cam.json "$points" -o o.png --labels o.png
    expect_in err "usage: -o and --labels both name o.png"
    expect_exit 2 "$bin" synth -o pts.csv --truth missing/t.json
    expect_exit 2 "$bin" calibrate "$boards"/left0[1-5].csv --image-size 640x480 -o c2.json --poses missing/p.csv
    expect_exit 2 "$bin" fit "$points" --image-size 1920x1080 -o cam2.json --report missing/r.svg
    expect_exit 2 "$bin" overlay cam.json "$points" -o o2.png --labels missing/l.csv
    expect_in err "cannot write missing/l.csv: cannot create a file in missing: No such file or directory"
    left=$(ls -A | grep -v '^cam.json$\|^out$\|^err$')
    [[ -z "$left" ]] || fail "outputs left behind by failed or refused commands: $left"
    ;;
  file_size_limit)
    # ulimit -f 2 (2 KiB) is below a camera file (~6 KB): exit 2 naming the file and the reason,
    # no partial file (main died of SIGXFSZ leaving out.json.tmp.XXXXXX).
    for fallback in "" 1; do
      rm -f "$work"/out.json* "$work"/.camproj-*
      ( ulimit -f 2; CAMPROJ_TEST_NO_TMPFILE=$fallback exec "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/out.json" ) >"$work/out" 2>"$work/err"
      code=$?
      [[ $code -eq 2 ]] || fail "exit $code under ulimit -f (fallback '$fallback'):\n$(cat "$work/err")"
      expect_in err "cannot write .*out.json: File too large"
      [[ -z $(ls -A "$work" | grep -v '^out$\|^err$') ]] || fail "left behind: $(ls -A "$work")"
    done
    ;;
  full_disk)
    # A full file system (a 16 KiB tmpfs in a private mount namespace, filled to its last 4 KiB
    # page): exit 2 naming the file and "No space left on device", the old file kept, nothing
    # left. Needs the right to mount (root, or a user namespace): SKIPPED otherwise.
    if ! unshare -rm true 2>/dev/null && ! unshare -m true 2>/dev/null; then
      echo "SKIPPED [$case]: cannot create a mount namespace to mount a tmpfs"; exit 77
    fi
    cat >"$work/full.sh" <<'INNER'
set -u
bin=$1 data=$2 dir=$3
mount -t tmpfs -o size=16k tmpfs "$dir" 2>/dev/null || exit 77
printf '{"old": true}\n' >"$dir/cam.json"
head -c 8192 /dev/zero >"$dir/filler" 2>/dev/null
"$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$dir/cam.json" >/dev/null
code=$?
ls -A "$dir" >"$dir.list"
cp "$dir/cam.json" "$dir.cam"
exit $code
INNER
    mkdir -p "$work/mnt"
    unshare -m bash "$work/full.sh" "$bin" "$data" "$work/mnt" >"$work/out" 2>"$work/err" ||
      code=$?
    code=${code:-0}
    ((code == 77)) && { echo "SKIPPED [$case]: cannot mount a tmpfs"; exit 77; }
    ((code == 2)) || fail "exit $code on a full file system:\n$(cat "$work/err")"
    expect_in err "cannot write .*cam.json: .*No space left on device"
    [[ $(cat "$work/mnt.list" | tr '\n' ' ') == "cam.json filler " ]] || fail "left: $(cat "$work/mnt.list")"
    grep -q '"old"' "$work/mnt.cam" || fail "the old camera file was changed"
    ;;
  file_modes_and_links)
    # A new file honours the umask; a replaced one keeps its mode (main: always 0644).
    ( umask 077; exec "$bin" synth --seed 1 --points 10 -o "$work/new.csv" --truth "$work/new.json" ) >/dev/null 2>&1 || fail "synth failed"
    [[ $(stat -c %a "$work/new.csv") == 600 ]] || fail "umask 077 gave $(stat -c %a "$work/new.csv")"
    printf 'old' >"$work/cam.json"
    chmod 640 "$work/cam.json"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/cam.json"
    [[ $(stat -c %a "$work/cam.json") == 640 ]] || fail "replaced file's mode became $(stat -c %a "$work/cam.json")"
    # A symlinked output is written through: the link stays, its target gets the camera.
    mkdir -p "$work/real"
    ln -s real/target.json "$work/link.json"
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/link.json"
    [[ -L "$work/link.json" ]] || fail "the symlink was replaced by a file"
    grep -q '"fit"' "$work/real/target.json" || fail "the link's target holds no camera"
    # A 250-byte output name (main: the temporary name exceeded NAME_MAX).
    long=$(printf 'c%.0s' $(seq 1 245)).json
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/$long"
    [[ -s "$work/$long" ]] || fail "no 250-byte output"
    # A device is never replaced.
    expect_exit 2 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o /dev/null
    expect_in err "/dev/null: it is a character device"
    [[ -c /dev/null ]] || fail "/dev/null was replaced"
    ;;
  fifo_input_refused)
    # A FIFO with no writer (main: blocked forever) and a character device: refused at once.
    # timeout 20: a generous bound for a run that takes milliseconds.
    mkfifo "$work/fifo.csv" "$work/fifo.json"
    expect_exit 2 timeout 20 "$bin" fit "$work/fifo.csv" --image-size 640x480
    expect_in err "fifo.csv: is a FIFO, expected a regular file"
    expect_exit 2 timeout 20 "$bin" export "$work/fifo.json"
    expect_in err "fifo.json: is a FIFO"
    expect_exit 2 timeout 20 "$bin" export /dev/zero
    expect_in err "/dev/zero: is a character device"
    expect_exit 2 timeout 20 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" "$work/fifo.csv" -o "$work/o.png"
    expect_in err "fifo.csv: is a FIFO"
    ;;
  out_of_memory_refused)
    # More points than the process can hold: exit 2 naming the file and what a point costs, no
    # output file, never "std::bad_alloc" (or, without the up-front check, the OOM killer). The
    # limit is an address-space one (ulimit -v) set from the binary's own need: the smallest
    # limit, in 16 MB steps, under which a 6-point fit runs, plus a margin. A sanitizer build
    # reserves terabytes of address space and cannot run under any such limit: SKIPPED there.
    if ! (ulimit -v 4000000; "$bin" --version >/dev/null 2>&1); then
      echo "SKIPPED [$case]: the binary does not start under a 4 GB address-space limit (a sanitizer build)"
      exit 77
    fi
    "$bin" synth --seed 1 --points 300000 --noise 0.5 -o "$work/big.csv" --truth "$work/t.json" >/dev/null
    "$bin" synth --seed 1 --points 6 --noise 0.5 -o "$work/small.csv" --truth "$work/t6.json" >/dev/null
    base=""
    for ((kb = 65536; kb <= 4000000; kb += 16384)); do
      if (ulimit -v $kb; "$bin" fit "$work/small.csv" --image-size 1920x1080 >/dev/null 2>&1); then
        base=$kb
        break
      fi
    done
    [[ -n $base ]] || fail "no address-space limit up to 4 GB lets a 6-point fit run"
    # 48 MB more: enough to read the 300 000 points (about 80 bytes a point with their ids), not
    # to fit them too (200 bytes a point, 60 MB): refused up front, before fitting.
    expect_exit 2 bash -c 'ulimit -v $1; exec "$2" fit "$3" --image-size 1920x1080 -o "$4"' _ \
      $((base + 49152)) "$bin" "$work/big.csv" "$work/big.json"
    expect_in err "big.csv: fitting its 300000 points needs about 60 MB (200 bytes a point"
    expect_not_in err "bad_alloc"
    [[ ! -e "$work/big.json" ]] || fail "a refused fit wrote its output"
    # 4 MB more: not even the points can be read; reported as out of memory, naming the file.
    expect_exit 2 bash -c 'ulimit -v $1; exec "$2" fit "$3" --image-size 1920x1080 -o "$4"' _ \
      $((base + 4096)) "$bin" "$work/big.csv" "$work/big.json"
    expect_in err "big.csv: out of memory reading it"
    expect_not_in err "bad_alloc"
    [[ ! -e "$work/big.json" ]] || fail "a fit out of memory wrote its output"
    # And the same file fits where the memory is there (the limit is not what refused it).
    expect_exit 0 bash -c 'ulimit -v $1; exec "$2" fit "$3" --image-size 1920x1080 -o "$4"' _ \
      $((base + 409600)) "$bin" "$work/big.csv" "$work/big.json"
    # An export too large for the memory (a 16000 x 16000 ST map, 2 GB of floats) says so in
    # words, writing nothing ("std::bad_alloc" before session 37).
    py - "$work/t6.json" "$work/huge.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
c["image_size"] = [16000, 16000]
c["intrinsics"].update(fx=9000, fy=9000, cx=7999.5, cy=7999.5, k1=-0.01)
for key in ("gl", "look_at", "perspective", "frustum", "fit"):
    c.pop(key, None)
c["frustum"] = {"near": 0.5, "far": 10}
json.dump(c, open(sys.argv[2], "w"))
PY
    expect_exit 2 bash -c 'ulimit -v $1; exec "$2" export "$3" --to stmap -o "$4"' _ \
      $((base + 409600)) "$bin" "$work/huge.json" "$work/huge.exr"
    expect_in err "camproj: error: out of memory: what this command builds does not fit"
    expect_not_in err "bad_alloc"
    [[ ! -e "$work/huge.exr" ]] || fail "an export out of memory wrote its output"
    ;;
  exit2_messages_name_the_file)
    # The audit of exit 2 (bad input): every file slot of every command, given a file that is
    # missing, a folder, or garbage, exits 2 with a message that names that file (issue #11).
    cam="$data/projector/truth.json"
    pts="$data/projector/points.csv"
    mkdir -p "$work/a_folder.csv"
    printf 'not a camera, points, photo or mesh\n\x01\x02 1,2\n' >"$work/garbage.txt"
    printf 'v 0 0 nope\n' >"$work/garbage.obj"
    slots=(
      "fit @ --image-size 1920x1080 -o $work/o1.json"
      "fit $pts --image-size 1920x1080 --intrinsics @ -o $work/o2.json"
      "fit $pts --image-size 1920x1080 --object-points @ -o $work/o3.json"
      "fit $pts --image-size 1920x1080 --bounds-mesh @ -o $work/o4.json"
      "export @"
      "export @ --to three"
      "project @ $pts"
      "project $cam @"
      "overlay @ $pts -o $work/o5.png"
      "overlay $cam @ -o $work/o6.png"
      "overlay $cam $pts @ -o $work/o7.png"
      "view @ $pts -o $work/o8.html"
      "view $cam @ -o $work/o9.html"
      "view $cam $pts --image @ -o $work/o10.html"
      "view $cam $pts --mesh @ -o $work/o11.html"
    )
    for slot in "${slots[@]}"; do
      bads=("$work/missing.csv" "$work/a_folder.csv" "$work/garbage.txt")
      # (fit's POINTS may be a folder of CSV files: an empty one is a usage error, exit 1.)
      [[ $slot == "fit @"* ]] && bads=("$work/missing.csv" "$work/garbage.txt")
      [[ $slot == *--bounds-mesh* || $slot == *--mesh* ]] && bads+=("$work/garbage.obj")
      for bad in "${bads[@]}"; do
        # shellcheck disable=SC2086  # the slot is a word list
        expect_exit 2 "$bin" ${slot//@/$bad}
        expect_in err "$bad"
      done
    done
    ;;
  export_lens)
    # The exports that render the lens (docs/exports.md, "Rendering the lens"), on the projector
    # with k1 = -0.15, k2 = 0.02. The STMap is checked against the model evaluated here
    # independently: undistort the pixel (Newton), the pinhole pixel + the render target's offset,
    # then Nuke's (x + 0.5) / W, 1 - (y + 0.5) / H; float32 values of ~1: 1e-6.
    py - "$data/projector/truth.json" "$work/lens.json" "$work/folded.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
for key in ("gl", "look_at"):
    c.pop(key, None)
c["intrinsics"]["k1"], c["intrinsics"]["k2"] = -0.15, 0.02
json.dump(c, open(sys.argv[2], "w"))
c["intrinsics"]["k1"] = -1.5  # folds over inside the image
json.dump(c, open(sys.argv[3], "w"))
PY
    expect_exit 0 "$bin" export "$work/lens.json" --to glsl --quiet
    expect_in out "^vec4 camproj_lens(vec4 eye) {"
    expect_in out "^const mat4 camproj_projection = mat4("
    ! grep -q "pinhole part only" "$work/err" || fail "glsl renders the lens but was warned:\n$(cat "$work/err")"
    expect_exit 0 "$bin" export "$work/lens.json" --to gl --quiet
    expect_in err "to render the lens export glsl (per vertex), stmap or distortion-mesh"
    expect_exit 0 "$bin" export "$work/lens.json" --to stmap -o "$work/map.tif"
    expect_in out "^# render target: [0-9]* x [0-9]* px, pixel = the camera's pinhole pixel + ("
    py - "$work/lens.json" "$work/map.tif" "$work/out" <<'PY'
import json, re, sys
import cv2
c = json.load(open(sys.argv[1])); k = c["intrinsics"]; W, H = c["image_size"]
m = re.search(r"render target: (\d+) x (\d+) px, pixel = the camera's pinhole pixel \+ \((-?\d+), (-?\d+)\)",
              open(sys.argv[3]).read())
Wt, Ht, ox, oy = map(int, m.groups())
image = cv2.imread(sys.argv[2], cv2.IMREAD_UNCHANGED)
assert image.shape == (H, W, 4) and image.dtype == "float32", (image.shape, image.dtype)
for u, v in ((0, 0), (W - 1, H - 1), (W // 2, H // 2), (100, H - 100), (W - 1, 0)):
    yd = (v - k["cy"]) / k["fy"]; xd = (u - k["cx"] - k["skew"] * yd) / k["fx"]
    rd = (xd * xd + yd * yd) ** 0.5; r = rd
    for _ in range(50):
        g = r * (1 + k["k1"] * r * r + k["k2"] * r ** 4); dg = 1 + 3 * k["k1"] * r * r + 5 * k["k2"] * r ** 4
        r -= (g - rd) / dg
    x, y = xd * r / rd, yd * r / rd
    qx = k["fx"] * x + k["skew"] * y + k["cx"] + ox; qy = k["fy"] * y + k["cy"] + oy
    b, g_, red, a = image[v, u]  # OpenCV reads R, G, B, A as channels 2, 1, 0, 3
    want = ((qx + 0.5) / Wt, 1 - (qy + 0.5) / Ht)
    assert abs(red - want[0]) < 1e-6 and abs(g_ - want[1]) < 1e-6 and a == 1, (u, v, red, g_, want)
PY
    [[ $? -eq 0 ]] || fail "the STMap disagrees with the model"
    expect_exit 0 "$bin" export "$work/lens.json" --to undistort-stmap -o "$work/undistort.exr"
    [[ -s $work/undistort.exr ]] || fail "no undistortion map"
    expect_exit 0 "$bin" export "$work/lens.json" --to distortion-mesh -o "$work/mesh.json"
    py -c '
import json, sys
m = json.load(open(sys.argv[1]))
assert m["max_interpolation_error_px"] <= 0.01 and len(m["undistorted_uv"]) == 2 * m["vertex_count"], m["step_px"]
' "$work/mesh.json" || fail "bad distortion mesh"
    expect_exit 0 "$bin" export "$work/lens.json" --to distortion-mesh -o "$work/mesh.obj"
    grep -q "^vt " "$work/mesh.obj" && grep -q "^f 1/1 2/2 " "$work/mesh.obj" || fail "bad OBJ mesh"
    # Refusals: exit 1 (usage) or 2 (a lens folding inside the image), no file written.
    expect_exit 1 "$bin" export "$work/lens.json" --to stmap
    expect_in err "give -o MAP.tif, MAP.tiff or MAP.exr"
    expect_exit 1 "$bin" export "$work/lens.json" --to stmap -o "$work/map.png"
    expect_in err "must end in .tif, .tiff or .exr"
    [[ ! -e $work/map.png ]] || fail "map.png written"
    expect_exit 2 "$bin" export "$work/folded.json" --to stmap -o "$work/folded.tif"
    expect_in err "folds over at normalized radius"
    [[ ! -e $work/folded.tif ]] || fail "folded.tif written"
    expect_exit 2 "$bin" export "$work/folded.json" --to glsl
    expect_in err "cannot export as glsl: the lens model does not cover the image"
    [[ ! -s $work/out ]] || fail "partial glsl on stdout"
    # -o writes any export atomically, and never over the camera file it reads.
    expect_exit 0 "$bin" export "$work/lens.json" --to glsl -o "$work/lens.glsl"
    grep -q "^vec4 camproj_lens" "$work/lens.glsl" || fail "lens.glsl lacks camproj_lens"
    cp "$work/lens.json" "$work/lens_copy.json"
    expect_exit 2 "$bin" export "$work/lens.json" --to glsl -o "$work/lens.json"
    cmp -s "$work/lens.json" "$work/lens_copy.json" || fail "the camera file was overwritten"
    ;;
  export_non_finite_refused)
    # fx = 1e308 overflowed the GL matrices to inf (gl) or null (json), exit 0; cx = 1e308 failed
    # gl/json but passed the others. Now every reader and exporter refuses both alike.
    for field in fx cx; do
      py -c '
import json, sys
d = json.load(open(sys.argv[1])); d["intrinsics"][sys.argv[2]] = 1e308
json.dump(d, open(sys.argv[3], "w"))' "$data/projector/truth.json" "$field" "$work/big_$field.json"
      # The reader refuses the camera, so every format alike: the two main wrote non-finite
      # numbers in for fx (gl, json) and the one it let through for cx (colmap).
      formats="gl json colmap"
      [[ $field == cx ]] && formats="colmap"
      for to in $formats; do
        expect_exit 2 "$bin" export "$work/big_$field.json" --to "$to"
        expect_in err "big_$field.json: intrinsics with frustum.near, frustum.far: "
        [[ ! -s "$work/out" ]] || fail "export $to of $field = 1e308 printed: $(head -c 300 "$work/out")"
      done
      expect_exit 2 "$bin" project "$work/big_$field.json" "$data/projector/points.csv"
      expect_exit 2 "$bin" overlay "$work/big_$field.json" "$data/projector/points.csv" -o "$work/o.png"
      [[ ! -e "$work/o.png" ]] || fail "overlay wrote for $field = 1e308"
    done
    ;;
  overlay_image_limits)
    # The output format follows the extension (main wrote PNG bytes to x.jpg) or is refused.
    expect_exit 0 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/o.jpg"
    [[ $(head -c 2 "$work/o.jpg" | od -An -tx1 | tr -d ' \n') == ffd8 ]] || fail "o.jpg is not a JPEG"
    expect_exit 1 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/o.bmp"
    expect_in err "o.bmp: the image format is chosen by the extension"
    # A 16384^2 PNG (about 500 KB of file, 805 MB decoded): refused from its header; max RSS stays
    # far below the decoded size (main decoded it first). Bound 400 MB: the binary's own
    # footprint is ~20 MB in Release and ~100 MB under ASan.
    py -c '
import struct, sys, zlib
w = h = 16384
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
z = zlib.compressobj(9)
row = bytes(w + 1)
body = b"".join(z.compress(row) for _ in range(h)) + z.flush()
sys.stdout.buffer.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)) + chunk(b"IDAT", body) + chunk(b"IEND", b""))' >"$work/huge.png"
    for size in "[16384, 16384]" "[1920, 1080]"; do
      py -c '
import json, sys
d = json.load(open(sys.argv[1])); d["image_size"] = json.loads(sys.argv[2])
json.dump(d, open(sys.argv[3], "w"))' "$data/projector/truth.json" "$size" "$work/cam.json"
      rss_kb=$(py -c '
import resource, subprocess, sys
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=open(sys.argv[-1] + ".err", "w"))
print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)' \
        "$bin" overlay "$work/cam.json" "$data/projector/points.csv" "$work/huge.png" -o "$work/big.png")
      [[ ${rss_kb%% *} -eq 2 ]] || fail "exit ${rss_kb%% *} for a 16384^2 PNG on a $size camera: $(cat "$work/big.png.err")"
      (( ${rss_kb##* } < 400000 )) || fail "max RSS ${rss_kb##* } KB for a 16384^2 PNG on a $size camera"
      [[ ! -e "$work/big.png" ]] || fail "wrote an overlay"
    done
    grep -q "beyond the 67108864 pixels" "$work/big.png.err" || grep -q "image is 16384x16384" "$work/big.png.err" || fail "$(cat "$work/big.png.err")"
    # A blank canvas of an absurd image size: refused naming the camera file (main: OpenCV's
    # allocation error, naming no file).
    py -c '
import json, sys
d = json.load(open(sys.argv[1])); d["image_size"] = [100000, 100000]
json.dump(d, open(sys.argv[2], "w"))' "$data/projector/truth.json" "$work/wide.json"
    expect_exit 2 "$bin" overlay "$work/wide.json" "$data/projector/points.csv" -o "$work/w.png"
    expect_in err "wide.json: the camera's image size 100000x100000 is beyond the 67108864 pixels"
    ;;
  messages_and_version)
    expect_exit 0 "$bin" --version
    # The version and the commit it was built from (12 hex digits, "+dirty" with local changes;
    # "unknown" outside a git checkout).
    expect_in out "^camproj [0-9]*\.[0-9]*\.[0-9]* (git \([0-9a-f]\{12\}\(+dirty\)\{0,1\}\|unknown\))$"
    # Only camproj's own message on stderr (main: OpenCV's "[ WARN:...] imread_" line too).
    expect_exit 2 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" "$work/missing.jpg" -o "$work/p.png"
    [[ $(wc -l <"$work/err") -eq 1 ]] || fail "stderr has more than camproj's message:\n$(cat "$work/err")"
    expect_in err "^camproj: error: .*missing.jpg: cannot open"
    # An id with a terminal escape, moved 300 px so that the summary names it: printed escaped.
    awk -F, 'BEGIN { OFS = "," } NR == 2 { print $0, "id" ; next } /^[-0-9]/ { row++; if (row == 3) { $4 += 300; print $0, "\033[31mred" } else print $0, "p" row; next } { print }' \
      "$data/synthetic/points.csv" >"$work/esc.csv"
    expect_exit 0 "$bin" fit "$work/esc.csv" --image-size 1280x800
    expect_in out '\\x1b\[31mred'
    ! grep -q $'\033' "$work/out" || fail "a raw ESC reached the terminal"
    ;;
  fit_matches_truth)
    # camproj fit with no options on synth scenes (a projector with lens shift, 30 points, 0.5 px
    # noise) lands within 4 of its own sigmas of the truth synth wrote, for the focal length, the
    # principal point and the eye. Per scene and parameter |error| > 4 sigma has probability
    # 6.3e-5 for a Gaussian error; the sigmas use a noise estimate pulled up toward the 1 px
    # prior, so less. Over the 6 parameters (Bonferroni) p = 1e-3 per scene is asserted as a rate
    # over 20 scenes (binomial bound at level 1e-6), seeds shifted by CAMPROJ_SEED_OFFSET.
    offset=${CAMPROJ_SEED_OFFSET:-0}
    for i in $(seq 1 20); do
      seed=$((i + offset))
      "$bin" synth --seed "$seed" --points 30 --noise 0.5 --principal-point-offset 0,0.4 \
        -o "$work/p$i.csv" --truth "$work/t$i.json" >/dev/null || fail "synth seed $seed"
      "$bin" fit "$work/p$i.csv" --image-size 1920x1080 -o "$work/c$i.json" >/dev/null 2>&1
      echo "$?" >"$work/rc$i"
    done
    py - "$work" <<'PY' || fail "fitted cameras against the truth"
import json, math, os, sys
work = sys.argv[1]
beyond = 0
answered = 0
for i in range(1, 21):
    if open(os.path.join(work, "rc%d" % i)).read().strip() != "0":
        continue  # a refusal is not a wrong camera (exit 3 says why)
    answered += 1
    cam = json.load(open(os.path.join(work, "c%d.json" % i)))
    truth = json.load(open(os.path.join(work, "t%d.json" % i)))
    sigma = cam["fit"]["sigma"]
    errors = {}
    for name in ("fx", "cx", "cy"):
        if name in sigma:
            errors[name] = cam["intrinsics"][name] - truth["intrinsics"][name]
    for axis, name in enumerate(("eye_x", "eye_y", "eye_z")):
        errors[name] = cam["look_at"]["eye"][axis] - truth["look_at"]["eye"][axis]
    worst = max(abs(e) / sigma[n] for n, e in errors.items())
    if worst > 4.0:
        beyond += 1
        print("scene %d: a parameter %.2f sigma from the truth: %s" % (i, worst, errors))
# The most failures of `answered` trials at p = 1e-3 that a test at level 1e-6 accepts.
p, level = 1e-3, 1e-6
def tail(n, k):
    return sum(math.comb(n, j) * p**j * (1 - p)**(n - j) for j in range(k + 1, n + 1))
bound = 0
while bound < answered and tail(answered, bound) > level:
    bound += 1
print("[ RATE ] fitted camera beyond 4 sigma of the truth: %d / %d (bound %d)" % (beyond, answered, bound))
sys.exit(0 if answered >= 15 and beyond <= bound else 1)
PY
    ;;
  calibrate_chessboard)
    # OpenCV's left chessboard views: one calibration without left02 (1.22 px RMS, 5x the others:
    # refused by name), 4 single corners left out by name (left13's corner 45 2.74 px off), the
    # model the views need (BIC: principal point, k1, k2, p1, p2; not aspect,
    # not k3, each with its reason), the intrinsics at the top level of the file (fit --intrinsics takes it: a
    # pose-only fit), each view a camera file export takes, the poses table one row per view; one
    # view alone is refused and writes nothing.
    boards="$data/real/opencv_chessboard"
    expect_exit 0 "$bin" calibrate "$boards"/left*.csv --image-size 640x480 -o "$work/left.json" --poses "$work/poses.csv"
    expect_in out "^calibrated 12 views, 644 points: rms 0.189"
    expect_in out "^left out point 45 of left13: 2.74 px from the calibrated camera (bound 0.924 px); --keep-all-points keeps it"
    expect_in out "^refused view left02: its 54 points are 1.22 px RMS from the camera the other views share"
    expect_in out "^  k1 "
    expect_in out "^  p1 "
    expect_not_in out "^  fy "
    expect_in out "^projection sigma: 0.697 px at the image centre, 2.85 px at the worst image corner"
    expect_in out "^model (BIC with sigma 0.138 px, estimated from the richest model):"
    expect_in out "^  principal-point freed: BIC -"
    expect_in out "^  aspect          left out: BIC +6.6 if freed"
    expect_in out "^  k3              left out: BIC +"
    expect_in out "^cross-validation: the even and the odd views calibrated apart (6 and 6) put the image's pixels [0-9.]* px apart"
    [[ $(wc -l <"$work/poses.csv") -eq 13 ]] || fail "poses.csv has not 12 rows:\n$(cat "$work/poses.csv")"
    expect_exit 0 "$bin" fit "$boards/left03.csv" --image-size 640x480 --intrinsics "$work/left.json" -o "$work/v3.json"
    expect_in out "model: pose, 6 free parameters"
    # The issue's name for it: a folder of frames, poses only, against the calibration.
    mkdir "$work/frames" && cp "$boards/left03.csv" "$boards/left05.csv" "$work/frames/"
    expect_exit 0 "$bin" fit "$work/frames" --image-size 640x480 --shared-intrinsics "$work/left.json" -o "$work/poses"
    [[ -f "$work/poses/left03.json" && -f "$work/poses/left05.json" ]] || fail "fit FOLDER --shared-intrinsics wrote no camera per view: $(ls "$work/poses")"
    py - "$work/poses/left05.json" "$work/left.json" <<'PY' || fail "a pose-only fit changed the shared intrinsics"
import json, sys
fitted, calibration = (json.load(open(p))["intrinsics"] for p in sys.argv[1:])
assert all(fitted[k] == calibration[k] for k in calibration), (fitted, calibration)
PY
    py - "$work/left.json" "$work/view3.json" <<'PY' || fail "views[2].camera is not a camera file"
import json, sys
calibration = json.load(open(sys.argv[1]))
assert calibration["views"][1]["name"] == "left03", calibration["views"][1]["name"]
assert [v["name"] for v in calibration["refused_views"]] == ["left02"], calibration["refused_views"]
json.dump(calibration["views"][1]["camera"], open(sys.argv[2], "w"))
PY
    expect_exit 0 "$bin" export "$work/view3.json" --to json
    expect_exit 0 "$bin" project "$work/view3.json" "$boards/left03.csv"
    # A view of one board row (its points on a line) has no pose: refused by name, the rest used.
    awk -F, 'NR <= 10' "$boards/left03.csv" >"$work/line03.csv"
    expect_exit 0 "$bin" calibrate "$boards"/left0[4-9].csv "$work/line03.csv" --image-size 640x480 -o "$work/line.json"
    expect_in out "^refused view line03 (9 points): its points lie on a line: no pose"
    expect_in out "^calibrated 6 views"
    expect_exit 3 "$bin" calibrate "$boards/left01.csv" --image-size 640x480 -o "$work/one.json"
    expect_in err "^camproj: cannot calibrate: 1 planar view determines at most 2 of the camera matrix's 4 free entries"
    [[ ! -e "$work/one.json" ]] || fail "a refused calibration wrote its file"
    mkdir "$work/right" && cp "$boards"/right*.csv "$work/right/"
    expect_exit 0 "$bin" calibrate "$work/right" --image-size 640x480 --fix aspect,principal-point,k2 -o "$work/right.json"
    expect_in out "^calibrated 12 views"
    expect_not_in out "^  fy "
    expect_exit 0 "$bin" calibrate "$work/right" --image-size 640x480 --keep-all-views \
      --keep-all-points --model principal-point+aspect+k1+k2 -o "$work/right.json"
    expect_in out "^calibrated 13 views, 702 points: rms 0.4"
    expect_not_in out "^model"
    expect_not_in out "^left out point"
    expect_exit 1 "$bin" calibrate "$work/right" --image-size 640x480 --model k2 -o "$work/bad.json"
    expect_in err "--model k2: k2 needs k1 too"
    expect_exit 1 "$bin" calibrate "$work/right" --image-size 640x480 --model opencv --fix k3 -o "$work/bad.json"
    expect_in err "--model opencv --fix k3: k3 is both freed and fixed"
    # A view named by a file name with a comma and a quote: its poses row is quoted (RFC 4180),
    # 22 fields like every other (23 before session 37).
    mkdir "$work/odd" && cp "$boards"/left0[3-6].csv "$work/odd/" && cp "$boards/left01.csv" "$work/odd/a,b \"q\".csv"
    expect_exit 0 "$bin" calibrate "$work/odd" --image-size 640x480 -o "$work/odd.json" --poses "$work/odd.csv"
    py -c '
import csv, sys
rows = list(csv.reader(open(sys.argv[1], newline="")))
assert all(len(r) == 22 for r in rows), [len(r) for r in rows]
assert "a,b \"q\"" in [r[0] for r in rows], [r[0] for r in rows]
' "$work/odd.csv" || fail "the poses CSV does not parse:\n$(cat "$work/odd.csv")"
    [[ ! -e "$work/bad.json" ]] || fail "a bad --model wrote a file"
    expect_not_in out "^refused view"
    ;;
  calibrate_view_column)
    # The left chessboard views in one CSV with a view column (rows interleaved, ids repeated
    # across views) calibrate exactly as the 13 files do: the same calibration (the covariance's
    # last bits aside, see same_calibration), poses byte for byte, the same summary; so do some
    # views in files and the rest in a view-column file.
    boards="$data/real/opencv_chessboard"
    expect_exit 0 "$bin" calibrate "$boards"/left*.csv --image-size 640x480 -o "$work/files.json" --poses "$work/files_poses.csv"
    grep -v '^wrote ' "$work/out" >"$work/files.out"
    views_csv "$work/all.csv" "$boards"/left*.csv
    [[ $(grep -c '^left03,1,' "$work/all.csv") -eq 1 && $(grep -c ',1,0.0,0.0,0.0,' "$work/all.csv") -eq 13 ]] \
      || fail "all.csv does not repeat id 1 once per view"
    expect_exit 0 "$bin" calibrate "$work/all.csv" --image-size 640x480 -o "$work/all.json" --poses "$work/all_poses.csv"
    expect_in out "^calibrated 12 views, 644 points: rms 0.189844 px"
    expect_in out "^refused view left02: its 54 points are 1.22 px RMS"
    expect_in out "^views (rms px): left01 0.195 left03 0.173 left04 "
    expect_in out "^wrote $work/all.json and $work/all_poses.csv"
    same_calibration "$work/files.json" "$work/all.json" || fail "the view column's calibration differs from the files':\n$(diff "$work/files.json" "$work/all.json" | head)"
    cmp -s "$work/files_poses.csv" "$work/all_poses.csv" || fail "the view column's poses differ"
    grep -v '^wrote ' "$work/out" | cmp -s - "$work/files.out" || fail "the summaries differ"
    # Mixed: left01-left07 in a view-column file, the others as files.
    views_csv "$work/first.csv" "$boards"/left0[1-7].csv
    expect_exit 0 "$bin" calibrate "$work/first.csv" "$boards"/left0[89].csv "$boards"/left1*.csv --image-size 640x480 -o "$work/mixed.json"
    same_calibration "$work/files.json" "$work/mixed.json" || fail "files and a view-column file together differ:\n$(diff "$work/files.json" "$work/mixed.json" | head)"
    # Bad input: exit 2, the file, line and field (or both sources of a name), no output file.
    awk 'NR == 30 { print; sub(/^left0[0-9],[0-9]+,/, "left03,2,") } { print }' "$work/all.csv" >"$work/dup.csv"
    expect_exit 2 "$bin" calibrate "$work/dup.csv" --image-size 640x480 -o "$work/dup.json"
    expect_in err "dup.csv: line 31, column 2 (id): duplicate id \"2\" in view \"left03\" (also on line 17)"
    [[ ! -e "$work/dup.json" ]] || fail "bad input wrote a calibration file"
    sed '20s/^left[0-9]*,/,/' "$work/all.csv" >"$work/unnamed.csv"
    expect_exit 2 "$bin" calibrate "$work/unnamed.csv" --image-size 640x480 -o "$work/unnamed.json"
    expect_in err "unnamed.csv: line 20, column 1 (view): empty view name"
    [[ ! -e "$work/unnamed.json" ]] || fail "bad input wrote a calibration file"
    expect_exit 2 "$bin" calibrate "$work/first.csv" "$boards/left05.csv" --image-size 640x480 -o "$work/twice.json"
    expect_in err "left05.csv: view name left05 is also the name of the view from $work/first.csv, line 6; every view needs its own name"
    [[ ! -e "$work/twice.json" ]] || fail "bad input wrote a calibration file"
    # A file without a view column but with repeated ids is still refused.
    printf 'id,X,Y,Z,u,v\na,0,0,0,1,1\nb,1,0,0,2,1\na,0,1,0,1,2\nc,1,1,0,2,2\n' >"$work/ids.csv"
    expect_exit 2 "$bin" calibrate "$work/ids.csv" --image-size 640x480 -o "$work/ids.json"
    expect_in err "ids.csv: line 4, column 1 (id): duplicate id \"a\" (also on line 2)"
    ;;
  calibrate_views_load_in_export_and_project)
    # A view of the calibration, selected by name (--view) or taken out as docs/calibration.md
    # says, is a camera file for export and project: projected through it, left05's corners land
    # on their pixels with the calibration's own RMS of that view (0.151 px).
    boards="$data/real/opencv_chessboard"
    views_csv "$work/all.csv" "$boards"/left*.csv
    expect_exit 0 "$bin" calibrate "$work/all.csv" --image-size 640x480 -o "$work/calib.json"
    expect_exit 0 "$bin" export "$work/calib.json" --view left05 --to gl
    expect_in out "^projection "
    expect_exit 0 "$bin" export "$work/calib.json" --view left05 --to json -o "$work/left05.json"
    py -c "import json, sys; json.dump(json.load(open(sys.argv[1]))['views'][3]['camera'], open(sys.argv[2], 'w'))" \
      "$work/calib.json" "$work/extracted.json"
    for camera in "--view left05 $work/calib.json" "$work/left05.json" "$work/extracted.json"; do
      expect_exit 0 "$bin" project $camera "$boards/left05.csv"
      py - "$work/out" "$boards/left05.csv" "$work/calib.json" <<'PY' || fail "left05 projected through $camera is off its pixels"
import csv, json, math, sys
projected = list(csv.DictReader(open(sys.argv[1])))
observed = list(csv.DictReader(open(sys.argv[2])))
assert len(projected) == len(observed) == 54, len(projected)
d = [math.hypot(float(p["u"]) - float(o["u"]), float(p["v"]) - float(o["v"])) for p, o in zip(projected, observed)]
rms = math.sqrt(sum(x * x for x in d) / len(d))
# The calibration's own RMS of the view (no corner of left05 is left out as an outlier; the
# camera file's 17 digits reproduce it to ~1e-12 px).
view = [v for v in json.load(open(sys.argv[3]))["views"] if v["name"] == "left05"][0]
assert view["num_points"] == 54 and abs(rms - view["rms_px"]) < 1e-9, (rms, view["rms_px"])
PY
    done
    expect_exit 0 "$bin" project "$work/calib.json" --view left05 "$boards/left05.csv"
    cp "$work/out" "$work/by_name.out"
    expect_exit 0 "$bin" project "$work/extracted.json" "$boards/left05.csv"
    cmp -s "$work/out" "$work/by_name.out" || fail "--view and the extracted camera project differently"
    # A calibration file over a camera file's 1 MB bound (hundreds of views) is read under the
    # calibration reader's 16 MB, as by export (project read it under 1 MB in session 44).
    py -c "import json, sys; c = json.load(open(sys.argv[1])); c['padding'] = 'x' * 1200000; json.dump(c, open(sys.argv[2], 'w'))" \
      "$work/calib.json" "$work/big_calib.json"
    expect_exit 0 "$bin" project "$work/big_calib.json" --view left05 "$boards/left05.csv"
    cmp -s "$work/out" "$work/by_name.out" || fail "a calibration file over 1 MB projects otherwise"
    # A calibration file is not one camera; a refused view or an unknown name is named.
    expect_exit 2 "$bin" export "$work/calib.json" --to gl
    expect_in err "calib.json: a calibration file of 12 views, not one camera: select a view by its name"
    expect_exit 2 "$bin" project "$work/calib.json" --view left02 "$boards/left02.csv"
    expect_in err "calib.json: view left02 was refused by the calibration (refused_views): it has no camera"
    expect_exit 2 "$bin" export "$work/calib.json" --view left10 --to gl
    expect_in err "calib.json: no view named left10; the views are left01, left03, left04, left05, left06, left07, left08, left09, left11, left12, ... (12 in all)"
    expect_exit 2 "$bin" export "$work/left05.json" --view left05 --to gl
    expect_in err "left05.json: not a calibration file (no views array)"
    ;;
  calibrate_mixed_planar_and_3d)
    # One synthetic camera (synth's default: 1920x1080, fovy 40 deg, fx = fy = 1483.638 px, the
    # principal point at the centre, no distortion) seen in 4 planar views and 4 views of a point
    # cloud, 30 points each, 0.3 px noise. With fx, fy, cx, cy, k1, k2 free, every intrinsic is
    # within 3 sigma of the truth and the cloud views pin the focal length (sigma 0.83 px); the
    # planar views alone leave it to 28.9 px. The automatic model (fx only: the rest left out by
    # BIC) is within 3 sigma too. --keep-all-points: the outlier stage would leave out plane3's 8th
    # point (1.28 px, at its bound: a chance of ~1 % per set at these noise levels), and this case
    # is about the model, not that stage.
    for seed in 1 2 3 4; do
      expect_exit 0 "$bin" synth --seed $seed --object plane --points 30 --noise 0.3 -o "$work/plane$seed.csv" --truth "$work/truth_plane$seed.json"
      expect_exit 0 "$bin" synth --seed $((seed + 10)) --object cloud --points 30 --noise 0.3 -o "$work/cloud$seed.csv" --truth "$work/truth_cloud$seed.json"
    done
    model=principal-point+aspect+k1+k2
    expect_exit 0 "$bin" calibrate "$work"/plane[1-4].csv "$work"/cloud[1-4].csv --image-size 1920x1080 --model $model --keep-all-points -o "$work/mixed.json"
    expect_in out "^calibrated 8 views, 240 points: rms 0.38"
    expect_not_in out "^refused view"
    expect_in out "^views (rms px): plane1 0.377 plane2 0.366 plane3 0.421 plane4 0.34 cloud1 0.392 cloud2 0.405 cloud3 0.402 cloud4 0.346"
    expect_exit 0 "$bin" calibrate "$work"/plane[1-4].csv --image-size 1920x1080 --model $model -o "$work/planes.json"
    expect_exit 0 "$bin" calibrate "$work"/plane[1-4].csv "$work"/cloud[1-4].csv --image-size 1920x1080 -o "$work/auto.json"
    expect_in out "^calibrated 8 views, 240 points"
    py - "$work" <<'PY' || fail "the mixed calibration is off the truth"
import json, sys
work = sys.argv[1]
truths = [json.load(open("%s/truth_%s%d.json" % (work, kind, s)))["intrinsics"] for kind in ("plane", "cloud") for s in range(1, 5)]
assert all(t == truths[0] for t in truths), "synth's cameras differ"
truth = truths[0]
mixed = json.load(open(work + "/mixed.json"))
for name in ("fx", "fy", "cx", "cy", "k1", "k2"):
    error = mixed["intrinsics"][name] - truth[name]
    assert abs(error) < 3 * mixed["sigma"][name], (name, mixed["intrinsics"][name], truth[name], mixed["sigma"][name])
assert 0.7 < mixed["sigma"]["fx"] < 1.0, mixed["sigma"]["fx"]
planes = json.load(open(work + "/planes.json"))
assert planes["sigma"]["fx"] > 20, planes["sigma"]["fx"]
auto = json.load(open(work + "/auto.json"))
assert list(auto["sigma"]) == ["fx"], auto["sigma"]
for name, value in auto["intrinsics"].items():
    bound = 3 * auto["sigma"]["fx"] if name in ("fx", "fy") else 1e-9
    assert abs(value - truth.get(name, 0.0)) < bound, (name, value, truth.get(name))
PY
    ;;
  calibrate_view_with_too_few_points)
    # A view of 3 points is refused by its file (and line, in a view-column file) before any
    # calibration: exit 2, nothing written, an existing calibration file left as it was.
    boards="$data/real/opencv_chessboard"
    head -4 "$boards/left05.csv" >"$work/few.csv"
    expect_exit 2 "$bin" calibrate "$boards"/left0[1-4].csv "$work/few.csv" --image-size 640x480 -o "$work/calib.json"
    expect_in err "^camproj: error: $work/few.csv: view few has 3 points; a view needs at least 4$"
    [[ ! -e "$work/calib.json" ]] || fail "a refused calibration wrote its file"
    views_csv "$work/all.csv" "$boards"/left0[1-4].csv "$work/few.csv"
    echo kept >"$work/calib.json"
    expect_exit 2 "$bin" calibrate "$work/all.csv" --image-size 640x480 -o "$work/calib.json" --poses "$work/poses.csv"
    expect_in err "^camproj: error: $work/all.csv, line 6: view few has 3 points; a view needs at least 4$"
    [[ $(cat "$work/calib.json") == kept && ! -e "$work/poses.csv" ]] || fail "a refused calibration changed the output files"
    head -2 "$boards/left05.csv" >"$work/one.csv"
    expect_exit 2 "$bin" calibrate "$boards"/left0[1-4].csv "$work/one.csv" --image-size 640x480 -o "$work/calib.json"
    expect_in err "one.csv: view one has 1 point; a view needs at least 4"
    ;;
  calibrate_other_camera_refused)
    # left03 seen by another camera (its pixels scaled by 1.3 about the image centre: a 30 %
    # longer focal length) among the left views of a view-column file: refused by name in the
    # summary and the file (as is left02, 5x the others' RMS), exit 0, and the rest calibrated
    # exactly as without it.
    boards="$data/real/opencv_chessboard"
    awk -F, 'BEGIN { OFS = "," } NR == 1 { print; next } { $4 = 319.5 + 1.3 * ($4 - 319.5); $5 = 239.5 + 1.3 * ($5 - 239.5); print }' \
      "$boards/left03.csv" >"$work/zoomed03.csv"
    views_csv "$work/left.csv" "$boards"/left*.csv
    expect_exit 0 "$bin" calibrate "$work/left.csv" "$work/zoomed03.csv" --image-size 640x480 -o "$work/with.json"
    expect_in out "^refused view zoomed03: its 54 points are 1.47 px RMS from the camera the other views share (0.471 px): another camera"
    expect_in out "^refused view left02: its 54 points are 1.22 px RMS"
    expect_in out "^calibrated 12 views, 644 points: rms 0.189844 px"
    expect_not_in out "^views (rms px):.*zoomed03"
    expect_in out "^wrote $work/with.json"
    expect_exit 0 "$bin" calibrate "$work/left.csv" --image-size 640x480 -o "$work/without.json"
    py - "$work/with.json" "$work/without.json" <<'PY' || fail "the refused view changed the calibration"
import json, sys
with_, without = (json.load(open(p)) for p in sys.argv[1:])
assert [v["name"] for v in with_["refused_views"]] == ["zoomed03", "left02"], with_["refused_views"]
assert with_["intrinsics"] == without["intrinsics"], (with_["intrinsics"], without["intrinsics"])
assert [v["name"] for v in with_["views"]] == [v["name"] for v in without["views"]]
PY
    # Kept on request, it is the worst view by far.
    expect_exit 0 "$bin" calibrate "$work/left.csv" "$work/zoomed03.csv" --image-size 640x480 --keep-all-views --keep-all-points -o "$work/kept.json"
    expect_in out "^calibrated 14 views, 756 points"
    # A view whose correspondences are shuffled (row i's pixel from row 13 i mod 54) fits no
    # image of a plane: left out by name before anything else, the rest calibrated exactly as
    # without it (it broke the joint refinement, "please report it", before session 37); kept
    # on request, the refusal says what to do.
    awk -F, 'NR == 1 { print; next } { p[NR - 2] = $1 "," $2 "," $3; q[NR - 2] = $4 "," $5; n = NR - 1 }
             END { for (i = 0; i < n; i++) print p[i] "," q[(i * 13) % n] }' "$boards/left02.csv" >"$work/shuffled02.csv"
    mkdir "$work/shuffled" && cp "$boards"/left0[13456].csv "$work/shuffled02.csv" "$work/shuffled/"
    mkdir "$work/clean" && cp "$boards"/left0[13456].csv "$work/clean/"
    expect_exit 0 "$bin" calibrate "$work/shuffled" --image-size 640x480 -o "$work/shuffled.json"
    expect_in out "^refused view shuffled02 (54 points): its points fit no view of a plane: the best homography leaves .* px RMS, the views' median 1.7 px"
    expect_exit 0 "$bin" calibrate "$work/clean" --image-size 640x480 -o "$work/clean.json"
    py - "$work/shuffled.json" "$work/clean.json" <<'PY' || fail "the shuffled view changed the calibration"
import json, sys
shuffled, clean = (json.load(open(p)) for p in sys.argv[1:])
assert shuffled["intrinsics"] == clean["intrinsics"], (shuffled["intrinsics"], clean["intrinsics"])
PY
    expect_exit 3 "$bin" calibrate "$work/shuffled" --image-size 640x480 -o "$work/kept2.json" --keep-all-views
    expect_in err "^camproj: cannot calibrate: the joint refinement cannot start: points of a view are behind its start camera"
    expect_not_in err "report"
    ;;
  calibrate_many_views)
    # A 504-view calibration (the 12 left views that fit, 42 times under other names, each copy's
    # board frame moved along X by a whole number of squares, so no copy repeats a view exactly:
    # that is refused; from one view-column file) writes a 1.4 MB file: the moving-camera
    # recipe's second step (fit --intrinsics) and --view read it; only a file over 16 MiB is
    # refused.
    boards="$data/real/opencv_chessboard"
    py - "$work/many.csv" "$boards"/left0[13-9].csv "$boards"/left1*.csv <<'PY'
import os, sys
with open(sys.argv[1], "w") as out:
    out.write("view,X,Y,Z,u,v\n")
    for copy in range(42):
        for path in sys.argv[2:]:
            name = os.path.splitext(os.path.basename(path))[0]
            for line in open(path).read().split("\n")[1:]:
                if line.strip():
                    x, rest = line.split(",", 1)
                    out.write("%s_%d,%r,%s\n" % (name, copy, float(x) + 16 * copy, rest))
PY
    expect_exit 0 "$bin" calibrate "$work/many.csv" --image-size 640x480 -o "$work/calib.json"
    expect_in out "^calibrated 504 views, 27048 points: rms 0.189592 px"
    [[ $(wc -c <"$work/calib.json") -gt 1048576 ]] || fail "the calibration file is not over 1 MiB"
    expect_exit 0 "$bin" fit "$boards/left03.csv" --image-size 640x480 --intrinsics "$work/calib.json"
    expect_in out "model: pose, 6 free parameters"
    expect_exit 0 "$bin" export "$work/calib.json" --view left14_41 --to json -o "$work/last.json"
    expect_exit 0 "$bin" project "$work/last.json" "$boards/left14.csv"
    [[ $(wc -l <"$work/out") -eq 55 ]] || fail "left14_41's camera projected not 54 points"
    { printf '{"image_size": [640, 480]'; head -c 16800000 /dev/zero | tr '\0' ' '; printf '}'; } >"$work/big.json"
    expect_exit 2 "$bin" fit "$boards/left03.csv" --image-size 640x480 --intrinsics "$work/big.json"
    expect_in err "big.json: larger than 16777216 bytes"
    expect_exit 2 "$bin" export "$work/big.json" --view left03_0
    expect_in err "big.json: larger than 16777216 bytes"
    ;;
  *) fail "unknown case" ;;
esac
echo "ok [$case]"
