#!/usr/bin/env bash
# The stability table (docs/stability.md): builds tests/stability_test in Release, runs it with
# CAMPROJ_STABILITY_TABLE set so that it writes one row per case, and assembles the page: what
# the suite checks, how its tolerances were chosen, the machine and command, then the rows.
#
# Usage: scripts/stability.sh [output.md]          (default: docs/stability.md)
# The build directory is scripts/build.sh's build/release unless CAMPROJ_BUILD_DIR names another
# (it must be configured as Release: the table reports times). Exits non-zero if a case failed,
# after writing the page (failed rows say FAIL).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="${CAMPROJ_BUILD_DIR:-$root/build/release}"
out="${1:-$root/docs/stability.md}"
cd "$root"

bash "$root/scripts/build_release.sh" "$build" stability.sh stability_test

rows=$(mktemp)
log=$(mktemp)
trap 'rm -f "$rows" "$log"' EXIT
test_binary="${build#"$root"/}/tests/stability_test"
command="CAMPROJ_STABILITY_TABLE=<rows> $test_binary"
echo "\$ $command"
status=0
CAMPROJ_STABILITY_TABLE="$rows" "$build/tests/stability_test" >"$log" 2>&1 || status=$?
grep -E '^\[  (PASSED|FAILED) ' "$log" || true
if [[ ! -s "$rows" ]]; then
  cat "$log" >&2
  echo "stability.sh: the test wrote no table" >&2
  exit 1
fi

cases=$(grep -c '^| [0-9]' "$rows")
failed=$(grep -c '| \*\*FAIL\*\* |$' "$rows" || true)
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
version() { dpkg-query -W -f='${Version}' "$1" 2>/dev/null || echo unknown; }
changes=$(git status --porcelain -- lib tests 2>/dev/null | awk '{print $2}' | tr '\n' ' ')
# The cases kept out of the suite because they expose library problems: the comments and case
# names inside `#ifdef CAMPROJ_STABILITY_KNOWN_BUGS` blocks of the test.
known=$(awk '/^#ifdef CAMPROJ_STABILITY_KNOWN_BUGS/ {inside = 1; print ""; next}
             /^#endif/ {inside = 0; next}
             inside && /^ *\/\// {sub(/^ *\/\/ ?/, ""); printf "%s ", $0}
             inside && /cases\.push_back/ {want = 1}
             inside && want && !/^ *\/\// && match($0, /"[A-Z][A-Za-z0-9]+"/) {
               printf "(case `%s`)", substr($0, RSTART + 1, RLENGTH - 2); want = 0}' tests/stability_test.cc |
        sed '/^$/d; s/^/- /')

{
  cat <<'EOF'
# Stability table

Every extreme case ends in the right camera or a clear, specific refusal, never a wrong camera.
`tests/stability_test.cc` holds one table of cases, each with its expected outcome: the right
camera within a tolerance derived below, or a named refusal (`SceneError::Reason` for the fitter,
`std::invalid_argument` for look-at). It covers fields of view from 0.1 to 170 degrees, world
offsets of 1e7 and units from 1e-6 to 1e6, principal points up to two image widths outside the
image, fx/fy = 10, near-planar and planar scenes, 3 to 7 points, collinear and coincident points,
pixel noise up to 10 px, 10-50 % outliers with RANSAC, points behind the camera, a camera inside
its point cloud, a mirrored world, degenerate look-ats, and GL export with near 1e-6 and far 1e9
or infinite in all four depth conventions (NO, ZO, and both reversed-Z). The suite runs in
`ctest` (Release and ASan+UBSan) like every other test; this page is its measured table.

## How "right" is judged

Every tolerance comes from the maths, as a named constant with its reason in the test; where a
case's expectation is a measured rate of a known weakness, the test says so with the measurement.

- **Noise-free fits: rounding bound.** To first order the fit's error in parameter j is
  `e_j = -[(J^T J)^-1 J^T r]_j`, so `|e_j| <= sigma_j(1 px) |r|_2` (Cauchy-Schwarz), where
  `sigma_j(1 px)` is the fit's own reported sigma at a pixel sigma of 1 px, i.e. `sqrt((J^T J)^-1)_jj`
  (this is "condition number x rounding", made per parameter), and `r` is what perturbs the data:
  the pixels' inconsistency with the true camera, evaluated in long double, plus a bound on the
  fitter's own rounding when it evaluates a residual (32 unit roundoffs of each term it adds up).
  The check is `|e_j| <= 2 sigma_j(1 px) |r|_2 + 16 ulp(returned value)`: the factor 2 covers the
  second-order terms, the ulps the rounding of the returned camera (which dominates with a world
  offset of 1e7). The error column gives the largest `|e_j|` as a fraction of its bound.
- **Fitted or refused as undetermined.** `fit.h` refuses (kDegenerate) when the scaled Jacobian's
  condition number exceeds 1e6. The suite computes the condition number at the true camera
  itself (central differences in long double, in the fitter's parameterization) and requires it
  below 1e6 for every case expected to fit and above 1e6 for every case expected to be refused as
  undetermined; the error column shows it as "condition at truth".
- **Noisy fits: consistent with the fit's stated uncertainty, where the fit says it holds.**
  Each noisy case runs 20 draws of pixel noise on its scene and asserts rates (`tests/seeds.h`:
  a binomial bound at level 1e-6, printed as `[ RATE ]` in the log). With the sigma the fit
  estimates from its residuals, each parameter's error in its reported sigmas is Student's t with
  `2N - p` degrees of freedom, and the error vector `e` (rotation, eye, free intrinsics) weighed
  by the reported covariance, `NEES = e^T Sigma^-1 e`, is `p F(p, 2N - p)`, for a linear Gaussian
  model: every parameter within the `1 - 1e-4 / p` two-sided t quantile (Bonferroni) and NEES
  below the 99.99 % F quantile.
  <a name="linearity"></a>Both rest on the linearization, which the fit checks itself
  (`FitResult::linearity`, in the camera file and the summary): along each principal direction
  of the covariance, both ways, at the edge of the 99.99 % region, it compares the sum of
  squares on the straight line (L) and re-minimized across it (the profile, F) with the
  quadratic model's rise P. A curved valley puts its floor `(L - F) / sigma^2` off the line and
  the region's edge at `c sqrt(P / F)`: the linearized NEES of an error on that edge is
  `(P + L - F) / F` times its true chi-square. The fit reports "linear" when that factor is at
  most 2 (the sigmas hold to sqrt 2 out to the 99.99 % region); the checks run on the draws
  reported linear, and their chance of failing is raised accordingly (the bounds stand where the
  true statistic is `1 / factor` of them; the rate uses each draw's own factor). The draws reported
  curved are counted, not failed: the fit said so itself. Where a case's curvature is certain
  (10 px noise on a lens shift of two widths, a plane 1 % thick with the full model, a 1-degree
  compact object) the fit must report it curved. The check is local: it sees the valley within
  the region around the estimate. At a 1-degree field of view with the full model, 20 of 820 draws
  (seed offsets 0-40) sat on a straight stretch of the valley with the truth further along it,
  and 17 of them failed NEES; that case's covariance is therefore not checked (its row says so),
  and its refusals (41 of 820: LM stops on its cost tolerance in the curved valley, short of the
  minimum) are a stated rate.
- **RANSAC: exact outlier set.** Outliers are moved at least 20 px from their pixel; the fitted
  camera predicts an inlier to well under 1 px, and an inlier with 0.5 px noise leaves the 4 px
  threshold with probability exp(-32), so the outlier set must come back exactly, in every one of
  the 20 noise draws; the camera is then judged by the noisy-fit checks above.
- **GL export.** For points from the near plane (1e-6) to the far plane (1e9, or up to 1e300 with an
  infinite far plane) on five pixels of an off-axis, skewed projector: everything finite; the
  GL pipeline's pixel (`GlPixelFromWorld`) and the pinhole pixel (`PixelFromWorld`) within float64
  rounding of the exact (long double) projection, propagated stage by stage (32 unit roundoffs of
  each magnitude, including the world-to-camera cancellation `(|X|_1 + |t|_1) / z`); the window
  depth within its rounding of the exact value from docs/conventions.md section 6; and the depth
  order right wherever two exact depths are further apart than their tolerances.
- **Look-at.** A refusal must be `std::invalid_argument` naming the problem. A pose built with `up`
  almost along the gaze must be right to `8 u (1 + (|eye| + |target|) / |gaze|) / sin(up, gaze)`
  (u = 2^-53, the unit roundoff), the rounding of `up x w` relative to its length.

## Columns

*error*: for fits, the worst relative intrinsic error (principal point and skew relative to the
focal length), the rotation error and the camera-centre error relative to the distance to the
points, then the check's own measure (fraction of the rounding bound, or sigmas and NEES); for
noisy cases, the draws reported curved, the draws beyond their sigmas among those reported linear
and the bound on them; for refusals, the message. *Jacobian condition*: `FitResult::jacobian_condition` at the solution.
*time*: `FitResult::time_ms` for fits, otherwise the wall time of the call; times are reported,
never asserted.

EOF
  echo "## Run"
  echo
  echo "| | |"
  echo "|---|---|"
  echo "| command | \`${CAMPROJ_BUILD_DIR:+CAMPROJ_BUILD_DIR=${build#"$root"/} }bash scripts/stability.sh\`, which ran \`$command\` from the repository root |"
  echo "| result | $cases cases, $((cases - failed)) pass, $failed fail |"
  echo "| date (UTC) | $(date -u +%Y-%m-%dT%H:%M:%SZ) |"
  echo "| git | $(git rev-parse --short HEAD 2>/dev/null || echo unknown)${changes:+ with uncommitted changes in ${changes% }} |"
  echo "| load average | $(cut -d' ' -f1-3 /proc/loadavg) (1, 5, 15 min; other work on the machine inflates the times) |"
  echo "| CPU | $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores online |"
  echo "| OS | $(. /etc/os-release && echo "$PRETTY_NAME"), kernel $(uname -r) |"
  echo "| compiler | $("$compiler" --version | head -1), CMAKE_BUILD_TYPE=Release |"
  echo "| Ceres, Eigen, OpenCV | $(version libceres-dev), $(version libeigen3-dev), $(version libopencv-dev) |"
  echo
  if [[ -n "$known" ]]; then
    echo "## Known issues (cases kept out of the suite)"
    echo
    echo "These cases expose library problems. They are in the test with their correct expectation,"
    echo "inside \`#ifdef CAMPROJ_STABILITY_KNOWN_BUGS\` so that the committed suite stays green; to run them,"
    echo "configure a build with \`-DCMAKE_CXX_FLAGS=-DCAMPROJ_STABILITY_KNOWN_BUGS\`."
    echo
    echo "$known"
    echo
  fi
  echo "## Cases"
  echo
  cat "$rows"
} >"$out"
echo "stability.sh: wrote ${out#"$root"/} ($cases cases, $failed failed)"
exit "$status"
