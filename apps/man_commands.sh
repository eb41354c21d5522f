#!/usr/bin/env bash
# The COMMANDS section of camproj.1 for help2man --include: each subcommand's --help, verbatim.
# Usage: man_commands.sh CAMPROJ_BINARY OUTPUT
set -euo pipefail
{
  echo "[COMMANDS]"
  for command in fit export project convert synth overlay; do
    echo ".SS camproj $command"
    echo ".nf"
    "$1" "$command" --help | sed -e 's/\\/\\\\/g' -e 's/^\([.'"'"']\)/\\\&\1/'
    echo ".fi"
  done
} >"$2"
