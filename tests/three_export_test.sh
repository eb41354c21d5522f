#!/usr/bin/env bash
# Runs tests/three_export_test.mjs (docs/exports.md's three.js snippets in node with web/node_modules'
# three). Usage: three_export_test.sh CAMPROJ DATA_DIR EXPORTS_MD WEB_DIR. Exit 77 (skipped) only
# without node; a missing three package is a failure (scripts/install-deps.sh installs it).
set -u
if ! command -v node >/dev/null; then
  echo "SKIP: node is not installed (scripts/install-deps.sh installs it)"
  exit 77
fi
if [[ ! -f "$4/node_modules/three/package.json" ]]; then
  echo "FAIL: $4/node_modules/three is missing: run scripts/install-deps.sh (npm ci in web/)" >&2
  exit 1
fi
exec node "$(dirname "$0")/three_export_test.mjs" "$@"
