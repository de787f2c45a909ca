#!/usr/bin/env bash
# Installs what building and testing incise needs on a fresh Debian/Ubuntu machine, only if
# missing: a C toolchain, curl, the Vulkan loader and Mesa's drivers, Xvfb, xdotool and
# the X11 libraries the preview window loads (apt), chromium for the tests only, and Rust
# with rustfmt and clippy (rustup).
set -euo pipefail

apt_install() {
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "$@"
}

missing=()
command -v cc >/dev/null 2>&1 || missing+=(build-essential)
command -v curl >/dev/null 2>&1 || missing+=(curl ca-certificates)
command -v pkg-config >/dev/null 2>&1 || missing+=(pkg-config)
# Vulkan loader + Mesa drivers: the GPU solver runs on any adapter, in CI on lavapipe.
# (`grep >/dev/null`, not `grep -q`: under pipefail, grep -q quitting early makes
# ldconfig die of SIGPIPE and the package look missing.)
ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1 || missing+=(mesa-vulkan-drivers)
ldconfig -p 2>/dev/null | grep 'libvulkan.so.1' >/dev/null || missing+=(libvulkan1)
# X virtual framebuffer for the preview-window test (xvfb-run needs xauth); the X11 client
# libraries winit loads at run time.
command -v xvfb-run >/dev/null 2>&1 || missing+=(xvfb)
command -v xauth >/dev/null 2>&1 || missing+=(xauth)
# xdotool drives the mouse in the preview's scalpel-drag test.
command -v xdotool >/dev/null 2>&1 || missing+=(xdotool)
ldconfig -p 2>/dev/null | grep 'libxkbcommon-x11.so.0' >/dev/null || missing+=(libxkbcommon-x11-0)
ldconfig -p 2>/dev/null | grep 'libXcursor.so.1' >/dev/null || missing+=(libxcursor1)
ldconfig -p 2>/dev/null | grep 'libXi.so.6' >/dev/null || missing+=(libxi6)
ldconfig -p 2>/dev/null | grep 'libXrandr.so.2' >/dev/null || missing+=(libxrandr2)
# The test command only (scripts/test.sh sets INCISE_TEST_DEPS=1): the headless browser
# the exercise report test opens report.html in.
if [ "${INCISE_TEST_DEPS:-0}" = "1" ]; then
    command -v chromium >/dev/null 2>&1 || missing+=(chromium)
fi
if [ ${#missing[@]} -gt 0 ]; then
    echo "installing system packages: ${missing[*]}"
    apt_install "${missing[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
    if [ -x "$HOME/.cargo/bin/cargo" ]; then
        export PATH="$HOME/.cargo/bin:$PATH"
    else
        echo "installing Rust (rustup, stable, minimal profile)"
        curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
        export PATH="$HOME/.cargo/bin:$PATH"
    fi
fi
if command -v rustup >/dev/null 2>&1; then
    rustup component list --installed 2>/dev/null | grep -q '^rustfmt' || rustup component add rustfmt
    rustup component list --installed 2>/dev/null | grep -q '^clippy' || rustup component add clippy
fi

# wgpu/Mesa print "XDG_RUNTIME_DIR is invalid" without one; give them a private one.
if [ -z "${XDG_RUNTIME_DIR:-}" ] || [ ! -d "${XDG_RUNTIME_DIR}" ]; then
    XDG_RUNTIME_DIR="$(mktemp -d)"
    export XDG_RUNTIME_DIR
fi
