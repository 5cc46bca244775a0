#!/usr/bin/env bash
# Renders the report.html of every example study in headless Chromium and fails on a console
# error, a missing image, an empty chart or a page that does not render.
#   tests/report_browser_check.sh BALANCE_DESIGN [CHROMIUM] [KEEP_DIR]
# KEEP_DIR, when given, keeps the runs and the screenshots (<example>.png) there.
set -euo pipefail
exe=${1:?usage: report_browser_check.sh BALANCE_DESIGN [CHROMIUM] [KEEP_DIR]}
chromium=${2:-chromium}
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [ -n "${3:-}" ]; then
  work=$3
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi
command -v gnuplot >/dev/null || echo "report_browser_check: gnuplot not installed: no charts to check" >&2

failures=0
fail() {
  echo "report_browser_check: $1" >&2
  failures=$((failures + 1))
}

for study in "$src"/studies/examples/*.yaml; do
  name=$(basename "$study" .yaml)
  out="$work/$name"
  rc=0
  "$exe" run "$study" --out "$out" >/dev/null 2>"$work/$name.run.err" || rc=$?
  # exit 3 (stopped early) and 4 (no optimum) still write their report
  if [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ] && [ "$rc" -ne 4 ]; then
    fail "$name: run failed with exit $rc: $(head -c 400 "$work/$name.run.err")"
    continue
  fi
  page="$out/report.html"
  if [ ! -s "$page" ]; then
    fail "$name: no report.html"
    continue
  fi
  if grep -q 'warning' "$work/$name.run.err"; then
    fail "$name: $(grep warning "$work/$name.run.err" | head -1)"
  fi

  # every chart has drawn something: each <svg> ... </svg> holds path elements
  awk -v name="$name" '
    /<svg/ { inside = 1; paths = 0; charts++ }
    inside && /<path/ { paths++ }
    inside && /<\/svg>/ { inside = 0; if (paths < 3) { print name ": chart " charts " is empty"; bad = 1 } }
    END { exit bad }' "$page" >&2 || fail "$name: an empty chart"

  # every image points at a file that exists (or is inline data)
  while IFS= read -r src_attr; do
    ref=${src_attr#src=\"}
    ref=${ref%\"}
    case "$ref" in
      data:*) ;;
      *) [ -e "$out/$ref" ] || fail "$name: missing image $ref" ;;
    esac
  done < <(grep -o '<img [^>]*src="[^"]*"' "$page" | grep -o 'src="[^"]*"' || true)

  profile=$(mktemp -d)
  log="$work/$name.chromium.log"
  shot="$work/$name.png"
  timeout 120 "$chromium" --headless --no-sandbox --disable-gpu --disable-background-networking \
    --disable-component-update --disable-sync --no-first-run --user-data-dir="$profile" \
    --enable-logging=stderr --v=0 --screenshot="$shot" --window-size=1280,2000 \
    "file://$page" >"$log" 2>&1 || fail "$name: chromium failed (log: $log)"
  rm -rf "$profile"
  # the page has no scripts: any console message is something going wrong
  if grep -q ':CONSOLE' "$log"; then
    fail "$name: console error: $(grep -E 'CONSOLE' "$log" | head -2)"
  fi
  if grep -qE 'Failed to load resource|net::ERR_' "$log"; then
    fail "$name: a resource failed to load: $(grep -E 'Failed to load resource|net::ERR_' "$log" | head -1)"
  fi
  if [ ! -s "$shot" ]; then
    fail "$name: no screenshot"
  fi
  echo "report_browser_check: $name ok ($(grep -c '<svg' "$page") charts)"
done

if [ "$failures" -ne 0 ]; then
  echo "report_browser_check: $failures failure(s)" >&2
  exit 1
fi
