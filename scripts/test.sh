#!/usr/bin/env bash
# Runs the test suite. Installs Mesa's software Vulkan driver (lavapipe) and the Vulkan loader
# first when they are missing and apt is available, so GPU tests can run without a GPU.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! ldconfig -p 2>/dev/null | grep -q libvulkan.so.1 || ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
  if command -v apt-get >/dev/null 2>&1; then
    SUDO=""
    [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q mesa-vulkan-drivers libvulkan1
  else
    echo "note: no apt-get; install Mesa's Vulkan drivers (lavapipe) yourself for the GPU tests" >&2
  fi
fi

# The Vulkan loader warns without a runtime directory; give it a private one.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
cargo test --release "$@"
