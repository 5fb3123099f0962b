#!/usr/bin/env bash
# Pose-graph benchmark on the 2D pose graphs of /work/shared/data/pose_graphs_2d, every peer on
# the same file in the same run:
#   * urbanslam graph (ESDF, incremental);
#   * ceres_pose_graph: the weighted batch optimum (Ceres LM, sparse Cholesky, one thread),
#     started from the file's vertices, or from dead reckoning through the back end's spanning
#     edges for edges-only files (what the filter starts from);
#   * MRPT's batch `graph-slam --2d --levmarq`.
# chi2 is sum e' Omega e over the file's edges (g2o convention), evaluated by the same code
# (PoseGraphIO) for every result. Times are wall times of each process (reading, solving and
# writing included), the median of REPEAT runs for urbanslam and Ceres (MRPT runs once).
# in_proc_* are the same runs' own timings, without process start-up and writing (urbanslam's
# time_s: read + filter; Ceres's total_s: read + initial guess + solve): the urbanslam binary
# loads ~180 shared libraries (MRPT, OpenCV...) and starts in ~0.3 s, Ceres's tool in ~0.01 s.
#
# Table 1: urbanslam vs Ceres (ratio = urbanslam chi2 / Ceres chi2, speedup = Ceres time /
#   urbanslam time), and urbanslam with --no-relinearise (the thesis filter, every edge
#   linearised once).
# Table 2: MRPT as before. MRPT needs VERTEX lines; edges-only files get dead-reckoned
#   vertices first (esdf_pose_graph --init). MRPT 2.5's graph-slam loads the graph as
#   CNetworkOfPoses2D, which drops the information matrices (its output has identity
#   information): it minimises the unweighted error, so mrpt_chi2 is its unweighted optimum
#   under the weighted metric. uw_* run urbanslam on MRPT's output file (same edges, identity
#   information) and give both chi2 values of that unweighted problem.
# Table 3: error against ground truth where the data set has it: ATE RMSE (m, positions after
#   the best rigid alignment) and mean absolute heading error (deg) (esdf_pose_graph --error).
#
# Usage: bench/esdf/run_pose_graphs.sh [BUILD_DIR]   (default build dir: build)
#   env URBANSLAM=...  ESDF_TOOL=...  CERES_TOOL=...  GRAPH_SLAM=...  DATA=dir  REPEAT=3
set -euo pipefail
# One core for every peer: Debian's CHOLMOD (used by urbanslam and by Ceres's sparse Cholesky)
# opens OpenMP parallel regions inside its factorisation; urbanslam keeps them on the calling
# thread itself, this makes the peers do the same (Ceres runs with num_threads = 1 anyway).
export OMP_THREAD_LIMIT=1
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
build="${1:-$root/build}"
URBANSLAM="${URBANSLAM:-$build/apps/urbanslam/urbanslam}"
ESDF_TOOL="${ESDF_TOOL:-$build/bench/esdf/esdf_pose_graph}"
CERES_TOOL="${CERES_TOOL:-$build/bench/esdf/ceres_pose_graph}"
GRAPH_SLAM="${GRAPH_SLAM:-/usr/bin/graph-slam}"
DATA="${DATA:-$root/../shared/data/pose_graphs_2d}"
REPEAT="${REPEAT:-3}"
for tool in "$URBANSLAM" "$ESDF_TOOL" "$CERES_TOOL" "$GRAPH_SLAM"; do
  [[ -x "$tool" ]] || { echo "missing executable: $tool (ceres_pose_graph needs libceres-dev)" >&2; exit 2; }
done
[[ -d "$DATA" ]] || { echo "missing data folder: $DATA" >&2; exit 2; }
[[ "$REPEAT" =~ ^[1-9][0-9]*$ ]] || { echo "REPEAT must be a positive integer" >&2; exit 2; }

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# dataset [ground truth]
datasets=(
  "se-sync/manhattan.g2o vertigo/manhattan/manhattanOlson3500_nodes_groundTruth.dat"
  "vertigo/manhattan/manhattanOlson3500.g2o vertigo/manhattan/manhattanOlson3500_nodes_groundTruth.dat"
  "se-sync/city10000.g2o.gz"
  "se-sync/intel.g2o"
  "se-sync/CSAIL.g2o"
  "se-sync/MIT.g2o"
  "se-sync/kitti_00.g2o"
  "se-sync/ais2klinik.g2o.gz"
  "vertigo/ring/ring.g2o vertigo/ring/ring.groundTruth.g2o"
  "vertigo/ringCity/ringCity.g2o vertigo/ringCity/ringCity.groundTruth.g2o"
  "hog-man/w10000.graph.gz"
)

now() { date +%s.%N; }
json() { sed -E "s/.*\"$1\":\"?([^,\"}]*).*/\1/" "$2"; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
t1="$work/table1"; t2="$work/table2"; t3="$work/table3"
printf "%-42s %6s %6s | %14s %8s | %14s %8s %5s | %8s %7s | %9s %9s %7s | %14s\n" dataset poses edges \
  urbanslam_chi2 time_s ceres_chi2 time_s iters chi2_ratio speedup in_proc_u in_proc_c speedup chi2_no_relin > "$t1"
printf "%-42s | %14s %8s | %14s %8s %3s | %9s %7s | %12s %12s %9s\n" dataset \
  urbanslam_chi2 time_s mrpt_chi2 time_s rc chi2_ratio speedup uw_urbanslam uw_mrpt uw_ratio > "$t2"
printf "%-42s %6s | %10s %9s | %10s %9s | %10s %9s\n" dataset matched \
  urb_ate_m urb_hdg_deg ceres_ate_m cer_hdg_deg mrpt_ate_m mrpt_hdg_deg > "$t3"
total_u=0; total_c=0; total_iu=0; total_ic=0
for entry in "${datasets[@]}"; do
  read -r d gt <<< "$entry"
  f="$DATA/$d"
  [[ -f "$f" ]] || { printf "%-42s absent\n" "$d" | tee -a "$t1" >> "$t2"; continue; }
  name="$(basename "$d")"; name="${name%%.*}"
  : > "$work/tu"; : > "$work/tc"; : > "$work/iu"; : > "$work/ic"
  for ((r = 0; r < REPEAT; ++r)); do
    a=$(now)
    "$URBANSLAM" graph "$f" --json --out "$work/$name.esdf.g2o" > "$work/$name.json"
    b=$(now)
    "$CERES_TOOL" "$f" --out "$work/$name.ceres.g2o" > "$work/$name.ceres.json"
    c=$(now)
    echo "$b - $a" | bc -l >> "$work/tu"
    echo "$c - $b" | bc -l >> "$work/tc"
    json time_s "$work/$name.json" >> "$work/iu"
    json total_s "$work/$name.ceres.json" >> "$work/ic"
  done
  tu=$(median < "$work/tu"); tc=$(median < "$work/tc"); iu=$(median < "$work/iu"); ic=$(median < "$work/ic")
  total_u=$(echo "$total_u + $tu" | bc -l); total_c=$(echo "$total_c + $tc" | bc -l)
  total_iu=$(echo "$total_iu + $iu" | bc -l); total_ic=$(echo "$total_ic + $ic" | bc -l)
  chi2_u=$(json chi2 "$work/$name.json"); poses=$(json poses "$work/$name.json"); edges=$(json edges "$work/$name.json")
  chi2_c=$(json chi2 "$work/$name.ceres.json"); iters=$(json iterations "$work/$name.ceres.json")
  # The thesis filter (every edge linearised once): the effect of relinearisation.
  chi2_once=$("$URBANSLAM" graph "$f" --json --no-relinearise | sed -E 's/.*"chi2":([^,]*).*/\1/')
  ratio=$(awk -v a="$chi2_u" -v b="$chi2_c" 'BEGIN{ printf "%.4f", a / b }')
  speed=$(awk -v a="$tu" -v b="$tc" 'BEGIN{ printf "%.1fx", b / a }')
  ispeed=$(awk -v a="$iu" -v b="$ic" 'BEGIN{ printf "%.1fx", b / a }')
  printf "%-42s %6s %6s | %14.4f %8.3f | %14.4f %8.3f %5s | %8s %7s | %9.3f %9.3f %7s | %14.4f\n" "$d" "$poses" "$edges" \
    "$chi2_u" "$tu" "$chi2_c" "$tc" "$iters" "$ratio" "$speed" "$iu" "$ic" "$ispeed" "$chi2_once" >> "$t1"

  "$ESDF_TOOL" --init "$f" "$work/$name.init.g2o"
  a=$(now)
  rc=0
  "$GRAPH_SLAM" --2d --levmarq -i "$work/$name.init.g2o" -o "$work/$name.mrpt.g2o" > "$work/$name.mrpt.log" 2>&1 || rc=$?
  b=$(now)
  tm=$(echo "$b - $a" | bc -l)
  if [[ $rc -eq 0 && -f "$work/$name.mrpt.g2o" ]]; then
    chi2_m=$("$ESDF_TOOL" --eval "$f" "$work/$name.mrpt.g2o")
    uw_m=$("$ESDF_TOOL" --eval "$work/$name.mrpt.g2o" "$work/$name.mrpt.g2o")
    uw_u=$("$URBANSLAM" graph "$work/$name.mrpt.g2o" --json | sed -E 's/.*"chi2":([^,]*).*/\1/')
  else
    chi2_m=nan; uw_m=nan; uw_u=nan
  fi
  ratio=$(awk -v a="$chi2_u" -v b="$chi2_m" 'BEGIN{ if (b == "nan" || b + 0 == 0) print "n/a"; else printf "%.4f", a / b }')
  speed=$(awk -v a="$tu" -v b="$tm" 'BEGIN{ printf "%.1fx", b / a }')
  uw_ratio=$(awk -v a="$uw_u" -v b="$uw_m" 'BEGIN{ if (b == "nan" || b + 0 == 0) print "n/a"; else printf "%.4f", a / b }')
  printf "%-42s | %14.4f %8.3f | %14s %8.3f %3s | %9s %7s | %12.6g %12.6g %9s\n" "$d" \
    "$chi2_u" "$tu" "$chi2_m" "$tm" "$rc" "$ratio" "$speed" "$uw_u" "$uw_m" "$uw_ratio" >> "$t2"

  if [[ -n "${gt:-}" && -f "$DATA/$gt" ]]; then
    read -r ate_u hdg_u matched < <("$ESDF_TOOL" --error "$DATA/$gt" "$work/$name.esdf.g2o")
    read -r ate_c hdg_c _ < <("$ESDF_TOOL" --error "$DATA/$gt" "$work/$name.ceres.g2o")
    ate_m=nan; hdg_m=nan
    [[ $rc -eq 0 ]] && read -r ate_m hdg_m _ < <("$ESDF_TOOL" --error "$DATA/$gt" "$work/$name.mrpt.g2o")
    printf "%-42s %6s | %10.4f %9.4f | %10.4f %9.4f | %10s %9s\n" "$d" "$matched" \
      "$ate_u" "$hdg_u" "$ate_c" "$hdg_c" "$ate_m" "$hdg_m" >> "$t3"
  fi
done
printf "%-42s %13s | %14s %8.3f | %14s %8.3f %5s | %8s %7s | %9.3f %9.3f %7s |\n" "total (sum of medians)" "" "" "$total_u" "" \
  "$total_c" "" "" "$(awk -v a="$total_u" -v b="$total_c" 'BEGIN{ printf "%.1fx", b / a }')" "$total_iu" "$total_ic" \
  "$(awk -v a="$total_iu" -v b="$total_ic" 'BEGIN{ printf "%.1fx", b / a }')" >> "$t1"
echo "urbanslam vs Ceres (weighted batch optimum); times: median of $REPEAT runs"
cat "$t1"
echo
echo "urbanslam vs MRPT graph-slam (unweighted LM, see header)"
cat "$t2"
echo
echo "error against ground truth (rigid alignment)"
cat "$t3"
