#!/usr/bin/env bash
# Regenerates docs/performance.md's speed-against-accuracy figures: the charts of the bench
# reports (report.html, section "Speed against accuracy") of four example studies, full benches.
#   docs/figures/make-bench-figures.sh [BUILD_DIR]     run the benches (a few minutes of CPU)
#   docs/figures/make-bench-figures.sh --from DIR      use benches run before into DIR/free,
#                                                      DIR/rocker, DIR/driven, DIR/engine,
#                                                      DIR/engine-driven
set -euo pipefail
cd "$(dirname "$0")/../.."
out=docs/figures
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
source docs/figures/extract-chart.sh

if [ "${1:-}" = "--from" ]; then
  runs=${2:?"--from needs a folder"}
else
  bin=${1:-build}/bin/balance-design
  runs=$tmp/runs
  while read -r name study; do
    "$bin" bench "studies/examples/$study.yaml" --out "$runs/$name" >/dev/null 2>&1
  done <<LIST
free paper-fourbar
rocker triple-rocker-free
driven paper-fourbar-driven
engine engine-slider-crank-free
engine-driven engine-slider-crank
LIST
fi

# the paper four-bar, free: the five methods by their fronts, and two methods by integrator
extract_chart "$runs/free/report.html" work-precision-methods "$out/work-precision-methods.svg"
extract_chart "$runs/free/report.html" work-precision-mass-matrix \
  "$out/work-precision-mass-matrix.svg"
extract_chart "$runs/free/report.html" work-precision-opened-loop \
  "$out/work-precision-opened-loop.svg"
# the triple rocker through its limit positions: the opened loop by integrator
extract_chart "$runs/rocker/report.html" work-precision-opened-loop \
  "$out/work-precision-triple-rocker.svg"
# the engine slider-crank coasting: its two routes by their fronts, and each by integrator
extract_chart "$runs/engine/report.html" work-precision-methods \
  "$out/work-precision-engine-methods.svg"
extract_chart "$runs/engine/report.html" work-precision-truss "$out/work-precision-engine-truss.svg"
extract_chart "$runs/engine/report.html" work-precision-truss-dae \
  "$out/work-precision-engine-truss-dae.svg"
# driven: the RMS errors against the samples per revolution
extract_chart "$runs/driven/report.html" driven-convergence-error "$out/driven-convergence.svg"
extract_chart "$runs/engine-driven/report.html" driven-convergence-error \
  "$out/driven-convergence-engine.svg"
echo "wrote the bench figures in $out"
