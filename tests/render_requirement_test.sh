#!/usr/bin/env bash
# The render test without OpenGL (EGL's vendor list pointed at nothing): each case says skipped
# with the reason, and fails instead when CAMPROJ_REQUIRE_GL=1 (what .ci/run sets), so CI cannot
# go green without the render proof.
# Usage: render_requirement_test.sh RENDER_TEST_BINARY
set -u
bin=$1
out=$(mktemp)
trap 'rm -f "$out"' EXIT
one='--gtest_filter=*/RenderTest.*/Centered_NegativeOneToOne'
fail() { echo "FAIL: $*" >&2; cat "$out" >&2; exit 1; }

env -u CAMPROJ_REQUIRE_GL __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent "$bin" "$one" >"$out" 2>&1
[[ $? -eq 0 ]] || fail "without CAMPROJ_REQUIRE_GL the render test must skip, not fail"
grep -q '\[  SKIPPED \]' "$out" || fail "no case reported skipped"
grep -q 'no headless OpenGL: ' "$out" || fail "the skip does not say why"

CAMPROJ_REQUIRE_GL=1 __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent "$bin" "$one" >"$out" 2>&1
[[ $? -ne 0 ]] || fail "with CAMPROJ_REQUIRE_GL=1 and no OpenGL the render test passed"
grep -q 'CAMPROJ_REQUIRE_GL=1 but there is no headless OpenGL: ' "$out" || fail "the failure does not say why"
echo "render_requirement_test: skipped without OpenGL, failed when required"
