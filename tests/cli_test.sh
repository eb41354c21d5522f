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

case $case in
  fit_projector)
    expect_exit 0 "$bin" fit "$data/projector/points.csv" --image-size 1920x1080 -o "$work/cam.json" --trace
    # The projector's principal point is at the bottom edge and its pixels are square: the
    # automatic model frees the principal point and leaves the rest out, saying why.
    expect_in out "model: pose+focal+principal-point, 9 free parameters"
    expect_in out "fixed aspect = 1 (left out: BIC "
    grep -q '"left_out"' "$work/cam.json" || fail "camera file lacks left_out"
    grep -q '"selection"' "$work/cam.json" || fail "camera file lacks the model selection"
    expect_in out "residuals: rms"
    expect_in out "worst points:"
    expect_in out "iteration  elapsed_us  rms_px"
    [[ -f "$work/cam.json" ]] || fail "no camera file"
    grep -q '"fit"' "$work/cam.json" || fail "camera file lacks fit"
    # The fit is within a few sigma of the truth the data was made from.
    expect_exit 0 "$bin" export "$work/cam.json" --to gl
    expect_in out "^projection "
    ;;
  fit_json_stdout)
    expect_exit 0 "$bin" fit "$data/synthetic/points.csv" --image-size 1280x800 --json
    expect_in out '"rms_px"'
    expect_in out '"cam_from_world"'
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
    expect_in err "add points"
    cmp -s "$data/projector/truth.json" "$work/cam.json" || fail "the old camera file was changed"
    [[ $(ls "$work" | grep -c tmp) -eq 0 ]] || fail "a temporary file was left behind"
    ;;
  fit_ransac_lists_misclicked_points)
    # Points 3 and 7 of the synthetic scene moved by 200 px: RANSAC names them.
    awk -F, 'BEGIN { OFS = "," } /^[-0-9]/ { row++; if (row == 3 || row == 7) $4 += 200 } { print }' \
      "$data/synthetic/points.csv" >"$work/clicked.csv"
    expect_exit 0 "$bin" fit "$work/clicked.csv" --image-size 1280x800 --ransac 4 -o "$work/cam.json"
    expect_in out "left out of the fit (found by ransac): 2 of 50 points"
    expect_in out "  3 is "
    expect_in out "  7 is "
    grep -q '"outliers"' "$work/cam.json" || fail "camera file lacks the outliers"
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
    expect_in out "plane.csv	ok	pose+focal"
    expect_in out "line.csv	refused	the 3D points are collinear"
    expect_in out "broken.csv	bad input	.*line 2, column 3 (Z)"
    expect_in out "3 of 5 fitted"
    [[ -f "$work/out_cams/projector.json" && -f "$work/out_cams/synthetic.json" ]] || fail "missing camera files"
    [[ ! -e "$work/out_cams/line.json" && ! -e "$work/out_cams/broken.json" ]] || fail "camera file for a failed input"
    expect_exit 1 "$bin" fit "$work/in/projector.csv" "$work/in/synthetic.csv" --image-size 1920x1080
    expect_in err "needs -o"
    ;;
  fit_object_points)
    # Scene 85 of the click benchmark (clean, 8 points): the clicks lie on the front faces; the
    # default answers, but with the building's vertices as object points the camera must be
    # determined at its back corners too, and it is not (the mirrored reading parts there).
    cat >"$work/clicks.csv" <<'EOF'
X,Y,Z,u,v
-0.46658142326420854,0.9666607848537022,7.159444992645841,804,258
-0.5118561467638958,-1.1313561829389096,4.509209203986271,1013,509
-0.5118561467638958,1.1910858442418002,4.509209203986271,780,509
-0.5467799195000049,1.376529513331823,0,757,963
-0.5467799195000049,-1.376529513331823,0,1042,964
-0.5467799195000049,-1.376529513331823,2.3676037522919504,1039,722
-0.5467799195000049,1.376529513331823,2.3676037522919504,760,721
-0.46658142326420854,0.03106737102074586,7.159444992645841,896,257
EOF
    cut -d, -f1-3 >"$work/vertices.csv" <<'EOF'
X,Y,Z,u,v
-0.5467799195000049,-1.376529513331823,0,1041.4713945164417,962.9345668407349
0.5467799195000049,-1.376529513331823,0,1029.8543935564503,958.4351905395093
-0.5467799195000049,1.376529513331823,0,757.0705679015877,963.0746988957621
0.5467799195000049,1.376529513331823,0,767.6909976727264,958.5588949168766
-0.5467799195000049,-1.376529513331823,2.3676037522919504,1039.0820945994253,720.599504720215
0.5467799195000049,-1.376529513331823,2.3676037522919504,1027.827198946716,734.8158977407006
-0.5467799195000049,1.376529513331823,2.3676037522919504,759.4120964447881,720.4233646144736
0.5467799195000049,1.376529513331823,2.3676037522919504,769.6889784204042,734.670325333788
-0.5118561467638958,-1.1313561829389096,2.3676037522919504,1013.8831244763186,721.074488475116
0.24901973450193893,-1.1313561829389096,2.3676037522919504,1007.2618658660127,731.1527498957784
-0.5118561467638958,1.1910858442418002,2.3676037522919504,778.5776643320226,720.9268247365205
0.24901973450193893,1.1910858442418002,2.3676037522919504,784.8314780891858,731.0235525160971
-0.5118561467638958,-1.1313561829389096,4.509209203986271,1012.1669138130209,509.2332035657057
0.24901973450193893,-1.1313561829389096,4.509209203986271,1005.7307676972488,530.594004624445
-0.5118561467638958,1.1910858442418002,4.509209203986271,780.340470036445,508.8602650445106
0.24901973450193893,1.1910858442418002,4.509209203986271,786.4116102813146,530.2628946213258
-0.46658142326420854,0.03106737102074586,4.509209203986271,896.184406789495,510.38693561230315
0.21499707040357946,0.03106737102074586,4.509209203986271,896.0210346559219,529.5216711025754
-0.46658142326420854,0.9666607848537022,4.509209203986271,803.0690001410577,510.2377188595296
0.21499707040357946,0.9666607848537022,4.509209203986271,807.4184792141627,529.3875343767046
-0.46658142326420854,0.03106737102074586,7.159444992645841,896.2123184352762,257.43397301281266
0.21499707040357946,0.03106737102074586,7.159444992645841,896.0504035083201,288.28791298745625
-0.46658142326420854,0.9666607848537022,7.159444992645841,804.765142017897,257.18034996394135
0.21499707040357946,0.9666607848537022,7.159444992645841,808.9596073728086,288.0588110909621
EOF
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 -o "$work/cam.json"
    expect_exit 3 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 -o "$work/cam.json" \
      --object-points "$work/vertices.csv"
    expect_in err "world axis flipped"
    # The clicks themselves as object points: the same camera, judged over "the object points" too.
    expect_exit 0 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/clicks.csv"
    expect_in out "over the box the points span and the object points"
    # A bad object file is named; a robust loss, which skips the determination check, is refused.
    printf 'X,Y\n1,2\n' >"$work/bad.csv"
    expect_exit 2 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/bad.csv"
    expect_in err "bad.csv"
    expect_exit 1 "$bin" fit "$work/clicks.csv" --image-size 1920x1080 --object-points "$work/vertices.csv" \
      --model focal --loss huber:2
    expect_in err "object-points"
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
    expect_exit 0 "$bin" --help
    expect_in out "Exit codes"
    expect_exit 0 "$bin" fit --help
    expect_in out "Examples"
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
  project_points)
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$data/projector/points.csv"
    expect_in out "^id,X,Y,Z,u,v,depth"
    [[ $(wc -l <"$work/out") -eq 21 ]] || fail "expected 20 rows"
    printf 'X,Y,Z\n0,0,0\n' >"$work/xyz.csv"
    expect_exit 0 "$bin" project "$data/projector/truth.json" "$work/xyz.csv"
    ;;
  convert_round_trip)
    expect_exit 0 "$bin" convert --intrinsics 1000,1000,959.5,539.5 --image-size 1920x1080 --near 0.1 --far 100 --to frustum
    expect_in out "left -0.096"
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
    ;;
  overlay_png)
    expect_exit 0 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" -o "$work/o.png"
    [[ $(head -c 8 "$work/o.png" | od -An -tx1 | tr -d ' \n') == 89504e470d0a1a0a ]] || fail "not a PNG"
    expect_exit 2 "$bin" overlay "$data/projector/truth.json" "$data/projector/points.csv" "$work/missing.jpg" -o "$work/p.png"
    [[ ! -e "$work/p.png" ]] || fail "partial output"
    ;;
  *) fail "unknown case" ;;
esac
echo "ok [$case]"
