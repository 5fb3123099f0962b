#!/bin/sh
# Scan-alignment evaluation: success rate / CPU time of ICP, PL-ICP, CRF-match, CRF+ICP
# and MRPT's CICP on real scan pairs, and the NEES of the covariance methods.
# Usage: bench/alignment/run_alignment_bench.sh [BUILD_DIR] [extra alignment_bench args]
set -e
BUILD=${1:-build}
[ $# -gt 0 ] && shift
OUT=out/bench
mkdir -p "$OUT"
"$BUILD/bench/alignment/alignment_bench" --pairs 40 --json "$OUT/alignment.json" "$@" | tee "$OUT/alignment.txt"
