#!/bin/sh
# Installs the Debian 12 packages clothsim needs to build and test, only if
# something is missing (so repeated runs cost nothing). Needs root and apt.
set -eu
PACKAGES="build-essential cmake ninja-build pkg-config \
  libembree-dev libassimp-dev libosmesa6-dev libopenmpi-dev openmpi-bin \
  libopenvdb-dev libboost-iostreams-dev libpng-dev libcyaml-dev libyaml-dev \
  libcjson-dev libcmocka-dev libcairo2-dev libgmp-dev libhdf5-dev libxxhash-dev libplplot-dev plplot-driver-cairo valgrind python3 ffmpeg"
missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
[ -z "$missing" ] && exit 0
echo "installing:$missing"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
# shellcheck disable=SC2086
$SUDO apt-get install -y -q --no-install-recommends $missing
