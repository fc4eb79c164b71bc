#!/usr/bin/env bash
# The README's test command: installs the software Vulkan adapter (Mesa lavapipe)
# when it is missing, then runs the whole test suite in release mode.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1; then
    echo "installing Mesa's lavapipe Vulkan driver (mesa-vulkan-drivers)"
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq mesa-vulkan-drivers >/dev/null
fi

# The Python reader (the package in python/, `spatter-read`) is tested on files the
# simulator writes, installed into .venv as a user installs it.
if ! .venv/bin/python -c "import mcap, mcap_protobuf, numpy, pandas, matplotlib" >/dev/null 2>&1; then
    echo "setting up the Python reader's environment (.venv from tools/requirements.txt)"
    if ! python3 -m venv .venv >/dev/null 2>&1; then
        SUDO=""
        if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
        $SUDO apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq python3-venv >/dev/null
        python3 -m venv .venv
    fi
    .venv/bin/pip install -q --disable-pip-version-check -r tools/requirements.txt
fi
# The package itself, again on every run (a checkout's edits; a few seconds).
.venv/bin/pip install -q --disable-pip-version-check --no-deps ./python
rm -rf python/build python/*.egg-info

# Any writable folder keeps the Vulkan loader quiet.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
cargo test --release --locked "$@"
