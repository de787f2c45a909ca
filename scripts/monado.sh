#!/usr/bin/env bash
# Builds Monado, the open-source OpenXR runtime, once into a cache outside the source tree,
# and prints the path of its runtime manifest (the only line on stdout; progress goes to
# stderr). A later call reuses the build. The source is the tarball in ../shared/monado
# (see its README; checked against its sha256) when it is there, else upstream Monado's
# git repository fetched at the full pinned commit hash (git checks the objects against
# that hash; a fresh fetch cannot match the tarball's checksum). Installs, only if
# missing, the packages the build needs, the OpenXR loader, Mesa's lavapipe and the
# OpenXR core and Vulkan validation layers (apt).
#
#   INCISE_MONADO_SRC    folder holding monado-<commit>.tar.gz (default ../shared/monado)
#   INCISE_MONADO_GIT    Monado's git repository (default: upstream, gitlab.freedesktop.org)
#   INCISE_MONADO_CACHE  build folder (default ~/.cache/incise/monado-<commit>)
#   INCISE_MONADO_JOBS   parallel build jobs (default: the number of CPUs)
#
# Use: XR_RUNTIME_JSON=$(bash scripts/monado.sh) XRT_COMPOSITOR_NULL=1 SIMULATED_ENABLE=1 \
#      SIMULATED_LEFT=simple SIMULATED_RIGHT=simple incise xr config/plate_cut.ron --frames 120
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
src_dir="${INCISE_MONADO_SRC:-$(dirname "$repo")/shared/monado}"

fail() {
    echo "monado.sh: $*" >&2
    exit 1
}

# The source the project tested (shared/monado/README.md): its commit, the tarball's
# checksum, and upstream's repository.
commit=3b0f9380286f
full_commit=3b0f9380286f13d193d98ed505b02a09e5220c0a
sha256=340eb5303ba23818dfb4f10e329488802f4a49d6b2a407e7dc2f095b73657c1d
tarball="$src_dir/monado-$commit.tar.gz"
upstream="${INCISE_MONADO_GIT:-https://gitlab.freedesktop.org/monado/monado.git}"

cache="${INCISE_MONADO_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/incise/monado-$commit}"
build="$cache/build"
manifest="$build/openxr_monado-dev.json"
# A build from either source of the same commit.
stamp="$cache/built-$full_commit"

# Put the source of $full_commit in $cache/monado: the tarball (checksum checked), else a
# git fetch of upstream at that commit (git checks every object against the hash).
unpack_source() {
    if [ -f "$tarball" ]; then
        echo "$sha256  $tarball" | sha256sum -c --quiet - >&2 ||
            fail "$tarball does not match its checksum $sha256"
        tar -xzf "$tarball" -C "$cache"
        return
    fi
    echo "monado.sh: no $tarball; fetching Monado $full_commit from $upstream" >&2
    local git_dir="$cache/monado"
    git init -q "$git_dir" >&2
    # By hash (servers that allow it), else every branch (the commit is on master).
    if ! git -C "$git_dir" fetch -q --depth 1 "$upstream" "$full_commit" >&2 &&
        ! git -C "$git_dir" fetch -q "$upstream" '+refs/heads/*:refs/remotes/upstream/*' >&2; then
        rm -rf "$git_dir"
        fail "no Monado source: $tarball is missing and fetching $upstream at $full_commit failed (offline?). Put monado-$commit.tar.gz in INCISE_MONADO_SRC's folder, or let git reach $upstream (INCISE_MONADO_GIT names another clone); the XR runtime tests need one of them"
    fi
    git -C "$git_dir" -c advice.detachedHead=false checkout -q "$full_commit" >&2 ||
        fail "$upstream does not hold the pinned commit $full_commit"
    local got
    got="$(git -C "$git_dir" rev-parse HEAD)"
    [ "$got" = "$full_commit" ] || fail "$upstream gave commit $got, not the pinned $full_commit"
    git -C "$git_dir" fsck -q --no-dangling >&2 || fail "the fetched Monado repository is corrupt ($git_dir)"
}

apt_install() {
    local sudo=""
    [ "$(id -u)" -eq 0 ] || sudo="sudo"
    $sudo apt-get -o DPkg::Lock::Timeout=600 update -qq >&2
    DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 \
        install -y -qq "$@" >&2
}

# Packages: the build's (shared/monado/README.md) and, to run it, the loader, lavapipe and
# the validation layers the XR tests switch on.
wanted=(git cmake ninja-build build-essential pkg-config libeigen3-dev libvulkan-dev
    glslang-tools python3 libudev-dev libxcb1-dev libxcb-randr0-dev libx11-xcb-dev
    libx11-dev libxrandr-dev libopenxr-loader1 mesa-vulkan-drivers
    openxr-layer-corevalidation vulkan-validationlayers)
missing=()
for p in "${wanted[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "monado.sh: installing system packages: ${missing[*]}" >&2
    apt_install "${missing[@]}" || fail "installing ${missing[*]} failed"
fi

mkdir -p "$cache"
# One build at a time: tests running side by side wait for the first one's build.
exec 9>"$cache/lock"
flock 9

if [ ! -f "$stamp" ] || [ ! -f "$manifest" ]; then
    rm -rf "$cache/monado" "$build" "$cache"/built-*
    unpack_source
    echo "monado.sh: building Monado $commit in $cache (about a minute on 2 cores)" >&2
    log="$cache/build.log"
    off=()
    for d in ANDROID ARDUINO DAYDREAM DEPTHAI EUROC HANDTRACKING TWRAP HDK HYDRA ILLIXR NS \
        OHMD OPENGLOVES PSMV PSVR QWERTY REALSENSE REMOTE RIFT_S SURVIVE ULV2 VF VIVE WMR \
        SIMULAVR; do
        off+=("-DXRT_BUILD_DRIVER_$d=OFF")
    done
    if ! cmake -S "$cache/monado" -B "$build" -G Ninja \
        -DCMAKE_BUILD_TYPE=Release -DGIT_DESC="$commit" \
        -DBUILD_TESTING=OFF -DXRT_BUILD_SAMPLES=OFF \
        -DXRT_FEATURE_OPENXR=ON \
        -DXRT_FEATURE_COMPOSITOR_MAIN=ON -DXRT_FEATURE_COMPOSITOR_NULL=ON \
        -DXRT_FEATURE_SERVICE=OFF -DXRT_FEATURE_IPC=OFF \
        -DXRT_FEATURE_STEAMVR_PLUGIN=OFF -DXRT_FEATURE_WINDOW_PEEK=OFF -DXRT_FEATURE_TRACING=OFF \
        -DXRT_HAVE_OPENGL=OFF -DXRT_HAVE_OPENGLES=OFF -DXRT_HAVE_EGL=OFF -DXRT_HAVE_SDL2=OFF \
        -DXRT_HAVE_WAYLAND=OFF -DXRT_HAVE_DBUS=OFF -DXRT_HAVE_SYSTEMD=OFF \
        -DXRT_BUILD_DRIVER_SIMULATED=ON "${off[@]}" >"$log" 2>&1; then
        tail -n 30 "$log" >&2
        fail "configuring Monado failed (whole log: $log)"
    fi
    if ! ninja -C "$build" -j"${INCISE_MONADO_JOBS:-$(nproc)}" >>"$log" 2>&1; then
        tail -n 30 "$log" >&2
        fail "building Monado failed (whole log: $log)"
    fi
    [ -f "$manifest" ] || fail "the build wrote no runtime manifest $manifest"
    touch "$stamp"
fi
echo "$manifest"
