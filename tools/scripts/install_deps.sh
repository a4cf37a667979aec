#!/usr/bin/env bash
# Installs the Debian bookworm packages SiViFlow needs, only those missing (idempotent,
# non-interactive). Each package is described in third_party_notes.md.
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config
  mesa-vulkan-drivers libvulkan-dev vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools
  libglm-dev libtinygltf-dev libopenexr-dev libpng-dev libjpeg62-turbo-dev nlohmann-json3-dev
  libgtest-dev libbenchmark-dev
  libglfw3-dev libimgui-dev xvfb
  clang-15 libfuzzer-15-dev llvm-15
  munge slurmctld slurmd slurm-client
  blender openimageio-tools python3
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
