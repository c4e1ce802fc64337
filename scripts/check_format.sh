#!/usr/bin/env bash
# Checks that the project's C++ sources (every tracked .cpp/.h) are formatted by Debian's
# clang-format 14 with the committed .clang-format; prints the diff of each file that is not and
# exits 1. Fix with: bash scripts/check_format.sh --fix
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
CLANG_FORMAT=${LSF_CLANG_FORMAT:-clang-format-14}
LSF_FORMAT_SKIP='^$'  # files left out (an extended regex on the path); none

if ! command -v "$CLANG_FORMAT" >/dev/null; then
  echo "check_format: $CLANG_FORMAT not found (scripts/install_deps.sh installs clang-format-14)" >&2
  exit 1
fi
cd "$ROOT"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cpp' '*.h' | grep -Ev "$LSF_FORMAT_SKIP" || true)
else  # an exported tree without .git
  mapfile -t files < <(find fuzz include src test tools -name '*.cpp' -o -name '*.h' |
                       grep -Ev "$LSF_FORMAT_SKIP" | sort)
fi

if [ "${1:-}" = --fix ]; then
  "$CLANG_FORMAT" -i "${files[@]}"
  echo "check_format: formatted ${#files[@]} files"
  exit 0
fi

bad=0
for f in "${files[@]}"; do
  if ! diff -u --label "$f" --label "$f (clang-format)" "$f" <("$CLANG_FORMAT" "$f"); then
    bad=$((bad + 1))
  fi
done
if [ "$bad" -ne 0 ]; then
  echo "check_format: $bad of ${#files[@]} files differ from $CLANG_FORMAT's format (see the diffs" \
       "above; bash scripts/check_format.sh --fix)" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted as .clang-format says"
