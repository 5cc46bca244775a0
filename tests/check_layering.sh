#!/usr/bin/env bash
# Includes point one way only: core <- balance <- optimize <- studies <- cli. Within core, the
# files at its root and in core/detail/ (what any linkage shares) are the floor below the
# four-bar's own files in core/fourbar/ and never include them; core's internals (core/detail/,
# core/fourbar/detail/) are included by core's sources, tests and benchmarks only, never by a
# public header or a higher layer. Third-party headers stay behind their one door (yaml-cpp in
# studies/, CLI11 in cli/, NLopt and Ipopt in optimize/*.cpp, pybind11 in python/).
cd "$(dirname "$0")/.." || exit 1
fail=0
forbid() {  # forbid DESCRIPTION REGEX PATH...
  local what=$1 re=$2 hits
  shift 2
  hits=$(grep -rnE "#include [<\"]($re)" "$@" 2>/dev/null)
  if [ -n "$hits" ]; then
    echo "$what:"
    echo "$hits"
    fail=1
  fi
}
forbid "core/ includes a higher layer" '(balance|optimize|studies|cli|tests)/' core
forbid "core/'s shared floor includes the four-bar (core/fourbar/)" 'core/fourbar/' \
  $(ls core/*.hpp core/*.cpp 2>/dev/null) core/detail
forbid "a public core header includes core's internals" 'core/(fourbar/)?detail/' \
  $(ls core/*.hpp core/fourbar/*.hpp 2>/dev/null)
forbid "a layer above core includes core's internals" 'core/(fourbar/)?detail/' \
  balance optimize studies cli
forbid "balance/ includes a higher layer" '(optimize|studies|cli|tests)/' balance
forbid "optimize/ includes a higher layer" '(studies|cli|tests)/' optimize
forbid "studies/ includes a higher layer" '(cli|tests)/' studies
# core's two linkage types stand side by side: the four-bar knows nothing of the general engine,
# and the general engine sees the four-bar only where it maps one onto itself (from_fourbar)
forbid "core/fourbar/ includes the general engine (core/planar/)" 'core/planar/' core/fourbar
forbid "core/planar/ includes the four-bar outside from_fourbar" 'core/fourbar/' \
  $(ls core/planar/*.hpp core/planar/*.cpp 2>/dev/null | grep -v from_fourbar)
# inside studies/: study <- run <- {bench, sweep} <- report <- studies.hpp (the facade)
forbid "studies/study/ includes a higher floor of studies/" 'studies/(run|bench|sweep|report)/|studies/studies' \
  studies/study
forbid "studies/run/ includes a higher floor of studies/" 'studies/(bench|sweep|report)/|studies/studies' \
  studies/run
forbid "studies/bench/ includes a higher floor of studies/" 'studies/(sweep|report)/|studies/studies' \
  studies/bench
forbid "studies/sweep/ includes a higher floor of studies/" 'studies/(bench|report)/|studies/studies' \
  studies/sweep
forbid "studies/report/ includes the facade" 'studies/studies' studies/report
forbid "yaml-cpp outside studies/" 'yaml-cpp/' core balance optimize cli
forbid "CLI11 outside cli/" 'CLI/' core balance optimize studies
forbid "NLopt or Ipopt outside optimize/*.cpp" '(nlopt|coin/|coin-or/|IpIpopt)' \
  core balance studies cli $(ls optimize/*.hpp 2>/dev/null)
# the Python module (python/) sits on top, beside cli/: no library includes it or pybind11
forbid "a library includes the Python module" 'python/' core balance optimize studies cli
forbid "pybind11 outside python/" 'pybind11/' core balance optimize studies cli
[ $fail -eq 0 ] && echo "layering ok"
exit $fail
