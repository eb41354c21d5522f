#!/usr/bin/env bash
# Checks that camproj's hardening flags (CMakeLists.txt) reached what it builds: full RELRO (a
# GNU_RELRO segment and BIND_NOW) in the linked BINARY; stack canaries (calls to
# __stack_chk_fail) and, in optimized builds ("fortify" as $3), _FORTIFY_SOURCE's checked libc
# calls (__*_chk) in camproj's own objects, the static LIBRARY: the binary alone would not tell,
# since Debian's static libceres.a brings both.
# Usage: hardening_test.sh BINARY LIBRARY [fortify]
set -u
bin=$1
lib=$2
want_fortify=${3:-}
for tool in readelf nm; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIPPED: $tool not found (binutils)"
    exit 77
  fi
done
fail=0
check() { if eval "$2"; then echo "ok: $1"; else echo "FAIL: $1"; fail=1; fi; }
headers=$(readelf -W -l "$bin")
dynamic=$(readelf -W -d "$bin")
undefined=$(nm -u "$lib" 2>/dev/null)
check "GNU_RELRO segment in $bin" 'grep -q GNU_RELRO <<<"$headers"'
check "BIND_NOW in $bin (-z now: full RELRO)" 'grep -Eq "BIND_NOW|FLAGS.*NOW" <<<"$dynamic"'
check "stack canaries in $lib (__stack_chk_fail)" 'grep -q "U __stack_chk_fail" <<<"$undefined"'
if [[ "$want_fortify" == fortify ]]; then
  check "_FORTIFY_SOURCE in $lib (__*_chk calls)" 'grep -Eq "U __[a-z_]+_chk$" <<<"$undefined"'
fi
exit $fail
