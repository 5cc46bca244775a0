#!/usr/bin/env bash
# Regenerates the README's figures from real runs of the example studies (needs gnuplot).
#   docs/figures/make-figures.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
bin=${1:-build}/bin/balance-design
out=docs/figures
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" run studies/examples/paper-fourbar.yaml --out "$tmp/free" >/dev/null
"$bin" run studies/examples/paper-fourbar-driven.yaml --out "$tmp/driven" >/dev/null
"$bin" run studies/examples/triple-rocker-free.yaml --out "$tmp/triple" >/dev/null
"$bin" run studies/examples/paper-fourbar-balanced.yaml --out "$tmp/balanced" >/dev/null
"$bin" run studies/examples/paper-fourbar-driven-force-balanced.yaml --out "$tmp/driven-balanced" \
  >/dev/null
"$bin" run studies/examples/paper-fourbar-sweep.yaml --out "$tmp/sweep" --progress none >/dev/null
"$bin" run studies/examples/engine-slider-crank.yaml --out "$tmp/engine" >/dev/null
"$bin" run studies/examples/watt-sixbar.yaml --out "$tmp/watt" >/dev/null
"$bin" run studies/examples/watt-sixbar-balanced.yaml --out "$tmp/watt-balanced" >/dev/null
"$bin" run studies/examples/engine-slider-crank-balanced.yaml --out "$tmp/engine-balanced" \
  >/dev/null
"$bin" run studies/examples/watt-sixbar-optimized.yaml --out "$tmp/watt-optimized" >/dev/null

source docs/figures/extract-chart.sh
# the shaking-force hodograph of the driven paper four-bar, original and force balanced, straight
# from the run's report.html
extract_chart "$tmp/driven-balanced/report.html" hodograph "$out/report-hodograph.svg"
# the shaking moment over the sweep's 21 x 21 grid, original and force balanced, from the sweep's
# report.html
extract_chart "$tmp/sweep/report.html" sweep-Msh "$out/sweep-shaking-moment.svg"
# general planar linkages: the engine's slider-crank at 3000 rpm and the Watt six-bar
extract_animation "$tmp/engine/report.html" original "$out/engine-slider-crank-linkage.svg"
extract_chart "$tmp/engine/report.html" hodograph "$out/engine-slider-crank-hodograph.svg"
extract_animation "$tmp/watt/report.html" original "$out/watt-sixbar-linkage.svg"
extract_chart "$tmp/watt/report.html" joints "$out/watt-sixbar-joints.svg"
# balancing them: the Watt six-bar with its three counterweights, and the engine's shaking force
# before and after its crank counterweight
extract_animation "$tmp/watt-balanced/report.html" balanced "$out/watt-sixbar-balanced-linkage.svg"
extract_chart "$tmp/engine-balanced/report.html" hodograph \
  "$out/engine-slider-crank-balanced-hodograph.svg"
# the six-bar's least shaking moment among force-balanced designs against the added mass
extract_chart "$tmp/watt-optimized/report.html" pareto "$out/watt-sixbar-pareto.svg"

gnuplot <<GP
set datafile separator ','
set terminal svg size 720,400 dynamic font 'sans,12' background rgb 'white'
set key outside right top
set grid

set output '$out/paper-fourbar-angles.svg'
set title 'paper-fourbar: link angles in free motion (cf. paper Fig. 7)'
set xlabel 't [s]'; set ylabel 'angle [rad]'
plot '$tmp/free/timeseries.csv' every ::1 using 1:2 with lines lw 2 title 'θ1', \
     '' every ::1 using 1:3 with lines lw 2 title 'θ2', \
     '' every ::1 using 1:4 with lines lw 2 title 'θ3'

set output '$out/paper-fourbar-reactions.svg'
set title 'paper-fourbar: support reactions in free motion (cf. paper Fig. 8)'
set ylabel 'force on the ground [N]'
plot '$tmp/free/timeseries.csv' every ::1 using 1:11 with lines lw 2 title 'RA0x', \
     '' every ::1 using 1:12 with lines lw 2 title 'RA0y', \
     '' every ::1 using 1:13 with lines lw 2 title 'RA3x', \
     '' every ::1 using 1:14 with lines lw 2 title 'RA3y'

set output '$out/paper-fourbar-driven.svg'
set title 'paper-fourbar-driven: crank at 2π rad/s, one revolution'
set xlabel 'θ1 [rad]'; set ylabel '[N], [N m]'
set xrange [0:2*pi]
plot '$tmp/driven/timeseries.csv' every ::1 using 2:18 with lines lw 2 title 'drive torque τ', \
     '' every ::1 using 2:(sqrt(\$15**2+\$16**2)) with lines lw 2 title '|Fsh|', \
     '' every ::1 using 2:17 with lines lw 2 title 'Msh'

set output '$out/triple-rocker-free.svg'
set title 'triple-rocker-free: swinging through its limit positions'
set xlabel 't [s]'; set ylabel 'angle [rad]'
set autoscale x
plot '$tmp/triple/timeseries.csv' every ::1 using 1:2 with lines lw 2 title 'θ1', \
     '' every ::1 using 1:3 with lines lw 2 title 'θ2', \
     '' every ::1 using 1:4 with lines lw 2 title 'θ3', \
     1.552938 with lines dt 2 lc 'gray' title 'crank limit ±1.553 rad', \
     -1.552938 with lines dt 2 lc 'gray' notitle

set output '$out/paper-fourbar-balanced.svg'
set title 'paper-fourbar-balanced: support reactions of the force-balanced linkage (cf. paper Fig. 9)'
set xlabel 't [s]'; set ylabel 'force on the ground [N]'
plot '$tmp/balanced/timeseries.csv' every ::1 using 1:11 with lines lw 2 title 'RA0x', \
     '' every ::1 using 1:12 with lines lw 2 title 'RA0y', \
     '' every ::1 using 1:13 with lines lw 2 dt 2 title 'RA3x', \
     '' every ::1 using 1:14 with lines lw 2 dt 2 title 'RA3y', \
     '' every ::1 using 1:(\$15+\$16) with lines lw 3 lc 'black' title 'Fshx + Fshy (zero)'
GP
echo "wrote the figures in $out"
