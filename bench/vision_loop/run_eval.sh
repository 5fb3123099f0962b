#!/bin/sh
# Reproduces the Tree of Words figures: vocabulary reproducibility, precision-recall on
# the RTAB-Map loop sequence with the shipped vocabularies (trained on other images), and the
# speed benches. Usage: bench/vision_loop/run_eval.sh [BUILD_DIR] (default: build).
# Outputs: out/vision_loop/ (JSON per run, PR curves as CSV and PNG, bench.json).
set -eu
cd "$(dirname "$0")/../.."
BUILD=${1:-build}
U=$BUILD/apps/urbanslam/urbanslam
OUT=out/vision_loop
mkdir -p "$OUT"

# 1. The shipped vocabularies are what their recorded command produces (needs make deps).
if bench/vision_loop/training_images.sh > "$OUT/training_images.txt" 2>/dev/null; then
  cmp -s "$OUT/training_images.txt" share/vision_loop/training_images.txt || echo "note: training image list differs from the shipped one"
  for d in sift orb; do
    "$U" build-vocabulary share/vision_loop/training_images.txt --out "$OUT/${d}_k10_L4.usvoc" \
      --descriptor $d --k 10 --levels 4 --max-features 500 --threads 2 --quiet --json > "$OUT/build_$d.json"
    if cmp -s "$OUT/${d}_k10_L4.usvoc" "share/vision_loop/${d}_k10_L4.usvoc"; then
      echo "vocabulary $d: rebuilt bit-identical to share/vision_loop/${d}_k10_L4.usvoc"
    else
      echo "vocabulary $d: rebuilt file DIFFERS from the shipped one"
    fi
  done
else
  echo "skipping vocabulary rebuild: training packages missing (make deps)"
fi

# 2. Precision-recall on the full RTAB-Map sequence (84 frames, 44 loop frames).
R=../shared/data/images/rtabmap_samples
if [ -d "$R/samples" ]; then
  for d in sift orb; do
    for v in "" --no-verification "--sequence 1 --consistency 1"; do
      case $v in --no-verification) tag=${d}_bow_only ;; --seq*) tag=${d}_dbow2_scheme ;; *) tag=$d ;; esac
      "$U" eval-image-loop "share/vision_loop/${d}_k10_L4.usvoc" "$R/samples" --gt "$R/ground_truth_loops.txt" \
        --out "$OUT/rtabmap_$tag" --quiet --json $v > "$OUT/rtabmap_$tag.json"
      printf '%-22s ' "rtabmap $tag:"; cat "$OUT/rtabmap_$tag.json"
    done
  done
else
  echo "skipping RTAB-Map evaluation: $R not found"
fi
for d in sift orb; do
  "$U" eval-image-loop "share/vision_loop/${d}_k10_L4.usvoc" rawlogs/rtabmap-loop-excerpt \
    --gt rawlogs/rtabmap-loop-excerpt/ground_truth_loops.txt --out "$OUT/excerpt_$d" --quiet --json > "$OUT/excerpt_$d.json"
  printf '%-22s ' "excerpt $d:"; cat "$OUT/excerpt_$d.json"
done

# 3. Small images (160x120, a low-resolution camera): the RTAB-Map sequence shrunk to 160 px,
# and the simulated city's camera rendered at 160x120 (its true image loops by co-visibility).
# Plain, upscaled to 320 px before detection (the default), and upscaled with DBoW2's scheme
# instead of sequence matching (one query's islands, two consecutive queries agreeing).
lowres() {  # NAME VOCAB SEQUENCE GT [extra options]
  name=$1 voc=$2 seq=$3 gt=$4; shift 4
  extra="$*"
  for mode in "plain --min-image-side 0" "upscaled" "dbow2 --sequence 1 --consistency 1"; do
    tag=${mode%% *}; opts=${mode#"$tag"}
    # shellcheck disable=SC2086 # word splitting of the option lists is intended
    "$U" eval-image-loop "$voc" "$seq" --gt "$gt" --out "$OUT/lowres_${name}_$tag" --quiet --json $extra $opts > "$OUT/lowres_${name}_$tag.json"
    printf '%-34s ' "lowres $name $tag:"; cat "$OUT/lowres_${name}_$tag.json"
  done
}
if [ -d "$R/samples" ]; then
  for d in sift orb; do
    lowres "rtabmap_$d" "share/vision_loop/${d}_k10_L4.usvoc" "$R/samples" "$R/ground_truth_loops.txt" --max-image-side 160
  done
fi
C=$OUT/city160
sed -e 's/^width_px .*/width_px = 160/' -e 's/^height_px .*/height_px = 120/' -e 's/^cy_px .*/cy_px = 90/' \
  ini/city-camera.ini > "$OUT/city160.ini"
printf '\n[loops]\nimage_column_stride = 2\n' >> "$OUT/city160.ini"
"$U" simulate --ini "$OUT/city160.ini" --out "$C" --quiet --json > "$OUT/city160_simulate.json"
for d in sift orb; do
  lowres "city160_$d" "share/vision_loop/${d}_k10_L4.usvoc" "$C/city_Images" "$C/image_loops.txt"
done

# 4. The camera's planar relative pose on 1000 simulated street-view pairs: errors and NEES per
# covariance method. The first-order covariance's floors are calibrated on another city (seed 2)
# and evaluated on the table's (seed 1).
floors=$("$BUILD/bench/vision_loop/relative_pose_nees" 1000 --city-seed 2 --calibrate | grep -o -- '--floor-bearing-deg.*')
"$BUILD/bench/vision_loop/relative_pose_nees" 1000 $floors --json > "$OUT/relative_pose_nees.json"
printf '%-22s ' "relative pose NEES:"; cat "$OUT/relative_pose_nees.json"

# 5. The full planar pose (MetricRelativePose.h: the first image's features given depth by a
# second image half a second along the drive, the odometry's distance 2 % uncertain) on the same
# pairs: its three floors calibrated on seed 2, the mean NEES (3 if exact) on seed 1. The
# pipeline's [image_loop] metric_floor_* defaults are these floors, rounded.
floors=$("$BUILD/bench/vision_loop/relative_pose_nees" --metric 1000 --city-seed 2 --calibrate | grep -o -- '--floor-forward-m.*')
"$BUILD/bench/vision_loop/relative_pose_nees" --metric 1000 $floors --json > "$OUT/metric_pose_nees.json"
printf '%-22s ' "metric pose NEES:"; cat "$OUT/metric_pose_nees.json"

# 6. Speed: quantisation, query vs database size (10^3..10^6), vocabulary load, per frame.
"$BUILD/bench/vision_loop/vision_loop_bench" --benchmark_out="$OUT/bench.json" --benchmark_out_format=json
