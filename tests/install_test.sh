#!/usr/bin/env bash
# The installable package: `cmake --install BUILD` into a fresh temporary prefix installs the
# headers, the library, camprojConfig.cmake + its version file, the CLI (whose --version names
# the git revision) and its man page; then tests/consumer, a project that only does
# find_package(camproj), configures and builds against that prefix and runs.
# Usage: install_test.sh BUILD_DIR CONSUMER_SOURCE [extra cmake args for the consumer]
set -euo pipefail
build=$1
consumer=$2
shift 2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
fail() { echo "install_test: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "cmake --install failed"; }
for file in include/camproj/fit.h include/camproj/conventions.h lib/libcamproj.a \
            lib/cmake/camproj/camprojConfig.cmake lib/cmake/camproj/camprojConfigVersion.cmake \
            lib/cmake/camproj/camprojTargets.cmake bin/camproj share/man/man1/camproj.1; do
  [[ -f "$prefix/$file" ]] || fail "not installed: $file (installed: $(cd "$prefix" && find . -type f | sort | tr '\n' ' '))"
done
version=$("$prefix/bin/camproj" --version)
[[ "$version" =~ ^camproj\ [0-9]+\.[0-9]+\.[0-9]+\ \(git\ ([0-9a-f]{12}(\+dirty)?|unknown)\)$ ]] ||
  fail "--version printed \"$version\""
grep -q '^\.SH SYNOPSIS\|^\.SH DESCRIPTION' "$prefix/share/man/man1/camproj.1" || fail "the man page has no DESCRIPTION"
for command in fit export project convert synth overlay; do
  grep -q "^\.SS camproj $command$" "$prefix/share/man/man1/camproj.1" || fail "the man page has no section for camproj $command"
done

# The Python module, when the build has it (not in a sanitizer build): installed with its stub and
# importable from the prefix alone.
python_note="no Python module in this build"
if compgen -G "$build/python/camproj*.so" >/dev/null; then
  site=$(cd "$prefix" && find lib -name 'camproj*.so' -path '*dist-packages*' | head -1)
  [[ -n "$site" && -f "$prefix/$(dirname "$site")/camproj.pyi" ]] || fail "the Python module or its stub is not installed"
  module_dir="$prefix/$(dirname "$site")"
  PYTHONPATH="$module_dir" /usr/bin/python3 -c 'import camproj, sys; assert camproj.__file__.startswith(sys.argv[1]), camproj.__file__' "$module_dir" ||
    fail "the installed Python module does not import from $module_dir"
  python_note="the Python module imports from ${module_dir#"$prefix"/}"
fi

# The consumer sees only the prefix (no camproj source or build directory).
cmake -S "$consumer" -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" "$@" >"$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; fail "the consumer did not configure"; }
cmake --build "$work/consumer" >"$work/build.log" 2>&1 || { cat "$work/build.log"; fail "the consumer did not build"; }
out=$("$work/consumer/consumer")
# 12 exact points of a 500 px camera: the fit returns it to rounding; 2 fx / W = 1.5625.
[[ "$out" == "fx 500.000000, projection(0,0) 1.562500000" ]] || fail "the consumer printed \"$out\""
echo "install_test: installed into a fresh prefix, $version; $python_note; the consumer built and printed: $out"
