#!/usr/bin/env bash
# Every benchmark of bench/ on a Release build; results under results/bench_*/ as JSON.
#   bench/run_all.sh [BUILD_DIR]
set -euo pipefail
build=${1:-build}
bench/ngf_performance.sh "$build" results/bench_ngf
bench/silo_table2.sh "$build" results/bench_silo_table2
