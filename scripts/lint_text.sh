#!/usr/bin/env bash
# The repository describes the package as it is: no tracked file (code, configs, scripts, tests, docs) speaks of the
# rounds of work it was built in. Fails, listing the lines, when a tracked file has the word for a working round or
# an issue number; exits 77 (skipped) outside a git checkout.
# Usage: scripts/lint_text.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if ! git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  echo "lint_text.sh: skipped: $(pwd) is not a git checkout" >&2
  exit 77
fi
# Spelt in two parts so that this file does not match itself.
pattern="ses""sions?|iss""ue [0-9]+"
if git grep -niIwE "$pattern"; then
  echo "lint_text.sh: the lines above speak of how the package was built; say what it is instead" >&2
  exit 1
fi
echo "lint_text.sh: no tracked file speaks of working rounds or issue numbers"
