#!/usr/bin/env bash
# Install every Debian package fluidform needs to build, run and test (Debian 12).
# Idempotent: does nothing when all are present. Run as root (or with sudo available).
set -euo pipefail

PACKAGES=(
  # Vulkan loader, Mesa's lavapipe CPU driver, Khronos validation layer, vulkaninfo
  libvulkan1 mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  # static shaderc + glslang + SPIRV-Tools, linked by build.rs
  libshaderc-dev glslang-dev spirv-tools
  # C/C++ toolchain for the static link (libstdc++) and pkg-config
  build-essential pkg-config
  # DejaVu Sans for the benchmark plots
  fonts-dejavu-core
  # `fluidform view`: X11 libraries winit loads at run time, and Xvfb for its tests
  libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0 xvfb xauth
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all system packages present"
fi

# Rust toolchain: fluidform uses the machine's stable Rust (rustup); it is not a Debian package here.
if ! command -v cargo >/dev/null 2>&1 && [ ! -x "$HOME/.cargo/bin/cargo" ]; then
  echo "setup: no cargo found: install a stable Rust toolchain with rustup, then rerun" >&2
  exit 1
fi

# shaderc-sys finds libshaderc_combined.a here; .cargo/config.toml has the x86_64 default.
multiarch=$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)
if [ "$multiarch" != "x86_64-linux-gnu" ]; then
  echo "setup: on $multiarch, export SHADERC_LIB_DIR=/usr/lib/$multiarch before cargo"
fi
