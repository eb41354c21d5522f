#!/usr/bin/env bash
# The browser test without Chromium (CAMPROJ_CHROMIUM pointed at nothing found, PATH emptied of
# it): it says skipped with the reason, and fails instead when CAMPROJ_REQUIRE_BROWSER=1 (what
# .ci/run sets), so CI cannot go green without the browser proof.
# Usage: view_browser_requirement_test.sh VIEW_BROWSER_TEST_BINARY
set -u
bin=$1
out=$(mktemp)
trap 'rm -f "$out"' EXIT
one='--gtest_filter=ViewBrowserTest.OrbitViewScreenshotShowsTheScene'
fail() { echo "FAIL: $*" >&2; cat "$out" >&2; exit 1; }

env -u CAMPROJ_REQUIRE_BROWSER -u CAMPROJ_CHROMIUM PATH=/nonexistent "$bin" "$one" >"$out" 2>&1
[[ $? -eq 0 ]] || fail "without CAMPROJ_REQUIRE_BROWSER the browser test must skip, not fail"
grep -q '\[  SKIPPED \]' "$out" || fail "no case reported skipped"
grep -q 'no Chromium' "$out" || fail "the skip does not say why"

env -u CAMPROJ_CHROMIUM CAMPROJ_REQUIRE_BROWSER=1 PATH=/nonexistent "$bin" "$one" >"$out" 2>&1
[[ $? -ne 0 ]] || fail "with CAMPROJ_REQUIRE_BROWSER=1 and no Chromium the browser test passed"
grep -q 'CAMPROJ_REQUIRE_BROWSER=1 but there is no Chromium' "$out" || fail "the failure does not say why"
echo "view_browser_requirement_test: skipped without Chromium, failed when required"
