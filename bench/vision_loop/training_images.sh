#!/bin/sh
# Lists the real photographs the default vocabularies are trained on: every JPEG of the Debian
# package opencv-doc larger than 15 KB (sample images and tutorial photos) and the largest file
# of each wallpaper of plasma-workspace-wallpapers. None of them is in an evaluation sequence.
# Both packages are in DEB_PACKAGES (`make deps`). Usage: training_images.sh > list.txt
set -eu
for p in opencv-doc plasma-workspace-wallpapers; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
    { echo "training_images.sh: package $p is not installed (make deps)" >&2; exit 2; }
done
find /usr/share/doc/opencv-doc -iname '*.jpg' -size +15k | LC_ALL=C sort
for d in $(find /usr/share/wallpapers -type d -name images | LC_ALL=C sort); do
  ls -S "$d" | head -1 | sed "s|^|$d/|"
done
