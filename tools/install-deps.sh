#!/usr/bin/env bash
# Installs the Debian 12 packages bdptref builds and tests with (and nothing else).
# Skips apt entirely when everything is already installed.
set -euo pipefail
packages=(cmake g++ ninja-build libembree-dev libopenimageio-dev libopenexr-dev libtinygltf-dev
          nlohmann-json3-dev libstb-dev libglm-dev catch2 libtbb-dev libcli11-dev
          openimageio-tools     # NOT optional: OpenImageIO's CMake targets name /usr/bin/iconvert etc.
          git ca-certificates   # the build records the git revision; a clone needs git
          python3 parallel      # python3: bench/, scenes/ and reference-images/ scripts; parallel: docs/distributed.md
          clang libclang-rt-14-dev  # clang + libclang_rt.fuzzer: the libFuzzer target in fuzz/
          pybind11-dev python3-dev python3-numpy python3-pytest pkgconf)  # the Python module, examples/, bdptref.pc (docs/library.md)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
