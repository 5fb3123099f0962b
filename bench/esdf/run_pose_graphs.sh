#!/usr/bin/env bash
# Pose-graph benchmark: `urbanslam graph` (ESDF, incremental) vs MRPT's batch
# `graph-slam --2d --levmarq` on the 2D pose graphs of /work/shared/data/pose_graphs_2d, same
# file, same run. Prints one table row per dataset: final chi2 (sum e' Omega e over the file's
# edges, g2o convention, evaluated by the same code for both results) and wall time of each
# process (reading, solving and writing included). The last column is urbanslam with
# --no-relinearise (the thesis filter, every edge linearised once).
#
# Notes:
#  * MRPT needs VERTEX lines; edges-only files get dead-reckoned vertices first (esdf_pose_graph
#    --init, same edges and information matrices). graph-slam then computes its own initial
#    guess from a Dijkstra spanning tree.
#  * MRPT 2.5's graph-slam app loads the graph as CNetworkOfPoses2D, which drops the edges'
#    information matrices (its output file has identity information): it minimises the
#    unweighted error, so its chi2 here is of its unweighted optimum under the weighted metric.
#    For an apples-to-apples comparison with MRPT's own optimum, the last two columns run
#    urbanslam on MRPT's output file (same edges, identity information) and give both chi2
#    values of that unweighted problem (uw_*).
#
# Usage: bench/esdf/run_pose_graphs.sh [BUILD_DIR]   (default build dir: build)
#   env URBANSLAM=path/to/urbanslam  ESDF_TOOL=path/to/esdf_pose_graph  DATA=dir  GRAPH_SLAM=...
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
URBANSLAM="${URBANSLAM:-$build/apps/urbanslam/urbanslam}"
ESDF_TOOL="${ESDF_TOOL:-$build/bench/esdf/esdf_pose_graph}"
GRAPH_SLAM="${GRAPH_SLAM:-/usr/bin/graph-slam}"
DATA="${DATA:-$root/../shared/data/pose_graphs_2d}"
for tool in "$URBANSLAM" "$ESDF_TOOL" "$GRAPH_SLAM"; do
  [[ -x "$tool" ]] || { echo "missing executable: $tool" >&2; exit 2; }
done
[[ -d "$DATA" ]] || { echo "missing data folder: $DATA" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

datasets=(
  se-sync/manhattan.g2o
  vertigo/manhattan/manhattanOlson3500.g2o
  se-sync/city10000.g2o.gz
  se-sync/intel.g2o
  se-sync/CSAIL.g2o
  se-sync/MIT.g2o
  se-sync/kitti_00.g2o
  se-sync/ais2klinik.g2o.gz
  vertigo/ring/ring.g2o
  vertigo/ringCity/ringCity.g2o
  hog-man/w10000.graph.gz
)

now() { date +%s.%N; }
printf "%-42s %6s %6s | %14s %8s | %14s %8s %6s | %9s %7s | %14s | %12s %12s %9s\n" dataset poses edges \
  urbanslam_chi2 time_s mrpt_chi2 time_s rc chi2_ratio speedup chi2_no_relin uw_urbanslam uw_mrpt uw_ratio
for d in "${datasets[@]}"; do
  f="$DATA/$d"
  [[ -f "$f" ]] || { printf "%-42s absent\n" "$d"; continue; }
  name="$(basename "$d")"; name="${name%%.*}"
  t0=$(now)
  "$URBANSLAM" graph "$f" --json --out "$work/$name.esdf.g2o" > "$work/$name.json"
  t1=$(now)
  chi2_u=$(sed -E 's/.*"chi2":([^,]*).*/\1/' "$work/$name.json")
  poses=$(sed -E 's/.*"poses":([^,]*).*/\1/' "$work/$name.json")
  edges=$(sed -E 's/.*"edges":([^,]*).*/\1/' "$work/$name.json")
  # The thesis filter (every edge linearised once) for comparison: the effect of relinearisation.
  chi2_once=$("$URBANSLAM" graph "$f" --json --no-relinearise | sed -E 's/.*"chi2":([^,]*).*/\1/')
  "$ESDF_TOOL" --init "$f" "$work/$name.init.g2o"
  t2=$(now)
  rc=0
  "$GRAPH_SLAM" --2d --levmarq -i "$work/$name.init.g2o" -o "$work/$name.mrpt.g2o" > "$work/$name.mrpt.log" 2>&1 || rc=$?
  t3=$(now)
  if [[ $rc -eq 0 && -f "$work/$name.mrpt.g2o" ]]; then
    chi2_m=$("$ESDF_TOOL" --eval "$f" "$work/$name.mrpt.g2o")
    uw_m=$("$ESDF_TOOL" --eval "$work/$name.mrpt.g2o" "$work/$name.mrpt.g2o")
    uw_u=$("$URBANSLAM" graph "$work/$name.mrpt.g2o" --json | sed -E 's/.*"chi2":([^,]*).*/\1/')
  else
    chi2_m=nan; uw_m=nan; uw_u=nan
  fi
  tu=$(echo "$t1 - $t0" | bc -l); tm=$(echo "$t3 - $t2" | bc -l)
  ratio=$(awk -v a="$chi2_u" -v b="$chi2_m" 'BEGIN{ if (b == "nan" || b + 0 == 0) print "n/a"; else printf "%.4f", a / b }')
  speed=$(awk -v a="$tu" -v b="$tm" 'BEGIN{ printf "%.1fx", b / a }')
  uw_ratio=$(awk -v a="$uw_u" -v b="$uw_m" 'BEGIN{ if (b == "nan" || b + 0 == 0) print "n/a"; else printf "%.4f", a / b }')
  printf "%-42s %6s %6s | %14.4f %8.3f | %14s %8.3f %6s | %9s %7s | %14.4f | %12.6g %12.6g %9s\n" "$d" "$poses" "$edges" \
    "$chi2_u" "$tu" "$chi2_m" "$tm" "$rc" "$ratio" "$speed" "$chi2_once" "$uw_u" "$uw_m" "$uw_ratio"
done
