#!/usr/bin/env bash
# Every script of scripts/ that takes --help lists in it every option its argument loop accepts
# (the `--name)` labels of its `case`): a help that forgot one (evaluate-allocation.sh's --scenes)
# fails here. Only --help is run: nothing is built, rendered or written.
set -uo pipefail
root=${1:-$(dirname "$0")/..}
fail=0 checked=0
for script in "$root"/scripts/*.sh; do
  grep -qE '^\s*(-h\s*\|\s*)?--help\)' "$script" || continue
  name=$(basename "$script")
  if ! help=$(bash "$script" --help 2>&1); then
    echo "FAIL: $name --help exits non-zero"; fail=1; continue
  fi
  # the case labels: lines like "    --mfr) ...", "--build-dir | --prepare | --libs)"
  options=$(grep -oE '^\s*(-[a-z]\s*\|\s*)?--[a-z0-9-]+(\s*\|\s*--[a-z0-9-]+)*\)' "$script" |
    grep -oE -- '--[a-z0-9-]+' | sort -u)
  [ -n "$options" ] || { echo "FAIL: $name: no options found in its case labels"; fail=1; }
  for option in $options; do
    [ "$option" = "--help" ] && continue
    grep -qE -- "(^|[^a-z0-9-])$option([^a-z0-9-]|$)" <<<"$help" ||
      { echo "FAIL: $name --help does not mention $option"; fail=1; }
  done
  checked=$((checked + 1))
done
[ "$checked" -gt 0 ] || { echo "FAIL: no script with --help found under $root/scripts"; exit 1; }
[ "$fail" -eq 0 ] && echo "ok: $checked scripts list every option in --help"
exit "$fail"
