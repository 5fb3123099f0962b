# Sourced by the SLAM bench scripts with their arguments: the repository root as the working
# directory, BUILD_DIR and OUT_DIR (arguments 1 and 2), the CLI and the Freiburg data.
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${1:-build}
OUT=${2:-$BUILD/slam_eval}
U=$BUILD/apps/urbanslam/urbanslam
D=../shared/data/freiburg_slam_benchmark
