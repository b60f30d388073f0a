#!/usr/bin/env bash
# Checks that the tree has the project's style: clang-format (.clang-format) on the C++ and CUDA
# sources, ruff's formatter and linter (pyproject.toml) on the Python, no line over 120 columns in
# either, and no function over 80 lines outside the tests (scripts/check_function_length.py).
# `--fix` rewrites the files instead (function lengths are not fixed). Part of scripts/test.sh (CI).
set -euo pipefail
cd "$(dirname "$0")/.."
RUFF=${RUFF:-.venv/bin/ruff}
PYTHON=${PYTHON:-python3}
MAX_COLUMNS=120
mapfile -t cpp < <(git ls-files '*.cpp' '*.hpp' '*.cu' '*.cuh')
mapfile -t py < <(git ls-files '*.py')

if [ "${1:-}" = "--fix" ]; then
  clang-format -i "${cpp[@]}"
  "$RUFF" format --quiet .
  "$RUFF" check --fix --quiet .
  exit 0
fi

status=0
clang-format --dry-run -Werror "${cpp[@]}" || { echo "C++: run scripts/check_format.sh --fix"; status=1; }
"$RUFF" format --check --quiet . || { echo "Python: run scripts/check_format.sh --fix"; status=1; }
"$RUFF" check --quiet . || status=1
long=$(awk -v max="$MAX_COLUMNS" 'length > max {print FILENAME ":" FNR ": " length " columns"}' "${cpp[@]}" "${py[@]}")
"$PYTHON" scripts/check_function_length.py || status=1
if [ -n "$long" ]; then
  echo "lines over $MAX_COLUMNS columns:"
  echo "$long"
  status=1
fi
[ "$status" = 0 ] && echo "format: ${#cpp[@]} C++/CUDA and ${#py[@]} Python files pass"
exit "$status"
