#!/usr/bin/env bash
# Cuts a gzipped CARMEN log at its middle laser scan: DIR/first.clf holds every line up to that
# scan, DIR/second.clf the header lines (comments, PARAM: the sensor's description) and the rest.
# Shared by the localization and the multi-session benchmarks.
#
#   bench/localize/split_half.sh LOG.clf.gz DIR
set -euo pipefail
src=${1:?log} dir=${2:?folder}
mkdir -p "$dir"
half=$(($(zcat "$src" | grep -c '^FLASER') / 2))
zcat "$src" | awk -v h=$half '/^FLASER/{k++} k<=h {print}' > "$dir/first.clf"
zcat "$src" | awk -v h=$half '/^FLASER/{k++} k>h || /^#/ || /^PARAM/ {print}' > "$dir/second.clf"
