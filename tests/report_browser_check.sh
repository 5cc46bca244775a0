#!/usr/bin/env bash
# Renders the report.html of every example study in headless Chromium and fails on a console
# error, a missing image, an empty chart or a page that does not render; a single run's page
# must have its linkage animation, moving (two moments of the virtual clock, two pictures), and,
# where the run has harmonic orders, their bar chart. A sweep example's page
# is the sweep's (heat maps and tables from sweep.csv); it is also checked as an interrupted
# sweep leaves it: its rows cut to the first few and a last line cut short, the page rebuilt by
# `balance-design report DIR`.
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

# check_animating NAME PAGE: the first linkage animation of PAGE, alone on a page, rendered at
# two moments of Chromium's virtual clock gives two different pictures
check_animating() {
  local name=$1 page=$2
  local alone="$work/$name.animation.html"
  {
    echo '<!DOCTYPE html><html><body style="margin:0">'
    awk '/<svg class="animation"/ { on = 1 } on { print } on && /<\/svg>/ { exit }' "$page"
    echo '</body></html>'
  } >"$alone"
  local shots=()
  for ms in 100 1700; do
    local profile shot="$work/$name.animation-$ms.png"
    profile=$(mktemp -d)
    timeout 120 "$chromium" --headless --no-sandbox --disable-gpu --disable-background-networking \
      --disable-component-update --disable-sync --no-first-run --user-data-dir="$profile" \
      --virtual-time-budget="$ms" --screenshot="$shot" --window-size=900,700 \
      "file://$alone" >/dev/null 2>&1 || fail "$name: chromium failed on the animation"
    rm -rf "$profile"
    shots+=("$shot")
  done
  if [ ! -s "${shots[0]}" ] || [ ! -s "${shots[1]}" ]; then
    fail "$name: no picture of the animation"
  elif cmp -s "${shots[0]}" "${shots[1]}"; then
    fail "$name: the linkage animation does not move (the same picture at 0.1 s and 1.7 s)"
  fi
}

# check_page NAME OUT: the checks of OUT/report.html
check_page() {
  local name=$1 out=$2
  local page="$out/report.html"
  if [ ! -s "$page" ]; then
    fail "$name: no report.html"
    return
  fi

  # every chart has drawn something: each gnuplot <svg> ... </svg> holds path elements (the
  # linkage animations, drawn by the page itself, are checked below)
  awk -v name="$name" '
    /<svg/ && !/class="animation"/ { inside = 1; paths = 0; charts++ }
    inside && /<path/ { paths++ }
    inside && /<\/svg>/ { inside = 0; if (paths < 3) { print name ": chart " charts " is empty"; bad = 1 } }
    END { exit bad }' "$page" >&2 || fail "$name: an empty chart"
  local animations
  animations=$(grep -c '<svg class="animation"' "$page" || true)
  # one drawing per chart, none left out
  if command -v gnuplot >/dev/null &&
    [ "$(grep -c '<figure class="chart"' "$page")" -ne "$(($(grep -c '<svg' "$page") - animations))" ]; then
    fail "$name: a chart without its drawing"
  fi
  # a single run's page: the linkage animated (its shapes move by SMIL), and, where the run has
  # harmonic orders, a bar chart of them per design
  if [ -f "$out/timeseries.csv" ]; then
    if [ "$animations" -lt 1 ]; then
      fail "$name: no linkage animation"
    elif ! grep -q '<animate attributeName="points"' "$page"; then
      fail "$name: the linkage animation has nothing that moves"
    else
      check_animating "$name" "$page"
    fi
    if [ -f "$out/harmonics.csv" ] && command -v gnuplot >/dev/null &&
      ! grep -q 'id="chart-harmonics-original"' "$page"; then
      fail "$name: no harmonic bar chart"
    fi
  fi
  if grep -qiE '[^a-z]nan[^a-z]' "$page"; then
    fail "$name: NaN on the page: $(grep -oiE '.{30}[^a-z]nan[^a-z].{10}' "$page" | head -1)"
  fi

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
  echo "report_browser_check: $name ok ($(grep -c '<svg' "$page") charts and animations)"
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
  if grep -q 'warning' "$work/$name.run.err"; then
    fail "$name: $(grep warning "$work/$name.run.err" | head -1)"
  fi
  check_page "$name" "$out"

  # a sweep as an interruption leaves it: the first rows, a last line cut short, the page
  # rebuilt from the files
  if [ -f "$out/sweep.json" ]; then
    cut_dir="$work/$name-interrupted"
    rm -rf "$cut_dir"
    mkdir -p "$cut_dir"
    head -n 31 "$out/sweep.csv" >"$cut_dir/sweep.csv"
    sed -n 32p "$out/sweep.csv" | head -c 40 >>"$cut_dir/sweep.csv"
    sed -e 's/"status": "complete"/"status": "interrupted"/' -e 's/"done": [0-9]*/"done": 30/' \
      "$out/sweep.json" >"$cut_dir/sweep.json"
    if ! "$exe" report "$cut_dir" >/dev/null 2>"$work/$name-interrupted.err"; then
      fail "$name-interrupted: report failed: $(head -c 400 "$work/$name-interrupted.err")"
      continue
    fi
    grep -q 'Interrupted after 30 of' "$cut_dir/report.html" ||
      fail "$name-interrupted: the page does not say the sweep was interrupted"
    check_page "$name-interrupted" "$cut_dir"
  fi
done

if [ "$failures" -ne 0 ]; then
  echo "report_browser_check: $failures failure(s)" >&2
  exit 1
fi
