#!/usr/bin/env bash
# Checks that doc/method.md names only things that exist: every repository path in backticks (a
# word with a '/' ending in .h .cpp .py .yaml .launch .cfg .test or .md) must be a file of the
# repository, and every `name()` in backticks (also `Class::name()`) must occur as a word in src/,
# include/ or tools/ (the tools' own parts, e.g. tools/ros/bag_runner/). Prints each missing one
# and exits 1; exits 0 when all exist.
# Usage: bash scripts/check_docs.sh [markdown file...]   (default: doc/method.md)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
docs=("$@")
[ ${#docs[@]} -eq 0 ] && docs=(doc/method.md)

bad=0
for doc in "${docs[@]}"; do
  if [ ! -f "$doc" ]; then
    echo "check_docs: $doc not found" >&2
    exit 1
  fi
  # Backticked spans only (code blocks' lines have none that look like paths or calls).
  spans=$(grep -o '`[^`]*`' "$doc" | tr -d '`' || true)

  # Paths: relative to the repository root; a doc-relative link would not be in backticks.
  paths=$(grep -oE '^[A-Za-z0-9_.][A-Za-z0-9_./-]*/[A-Za-z0-9_.-]+\.(h|cpp|py|yaml|launch|cfg|test|md)$' \
            <<<"$spans" | sort -u || true)
  n_paths=0
  for p in $paths; do
    n_paths=$((n_paths + 1))
    if [ ! -f "$p" ]; then
      echo "check_docs: $doc names \`$p\`, which does not exist" >&2
      bad=1
    fi
  done

  # Functions: `name()` or `Scope::name()`; the last component must occur as a word in the code.
  funcs=$(grep -oE '^([A-Za-z_][A-Za-z0-9_]*::)*[A-Za-z_][A-Za-z0-9_]*\(\)$' <<<"$spans" |
            sort -u || true)
  n_funcs=0
  for f in $funcs; do
    n_funcs=$((n_funcs + 1))
    name=${f%()}
    name=${name##*::}
    if ! grep -rqw -- "$name" src include tools; then
      echo "check_docs: $doc names \`$f\`, but '$name' occurs nowhere in src/, include/ or tools/" >&2
      bad=1
    fi
    # A scope (Class::) must exist too.
    if [[ $f == *::* ]]; then
      scope=${f%::*}
      scope=${scope##*::}
      if ! grep -rqw -- "$scope" src include tools; then
        echo "check_docs: $doc names \`$f\`, but '$scope' occurs nowhere in src/, include/ or tools/" >&2
        bad=1
      fi
    fi
  done
  echo "check_docs: $doc: $n_paths paths, $n_funcs functions checked"
done
exit $bad
