#!/bin/sh
# configure.sh DIR TYPE: configures build folder DIR as CMAKE_BUILD_TYPE
# TYPE for scripts/test.sh and scripts/test-long.sh. A new folder gets
# Ninja, which starts every target's compiles at once (make waits for a
# target's libraries first and left a core idle behind the OpenVDB shim);
# a folder made before keeps its generator.
set -eu
generator=""
[ -f "$1/CMakeCache.txt" ] || generator="-GNinja"
# shellcheck disable=SC2086
cmake $generator -S . -B "$1" -DCMAKE_BUILD_TYPE="$2" >/dev/null
