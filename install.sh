#!/usr/bin/env bash
# Install workbench on a fresh Debian/Ubuntu machine: the system libraries for headless OpenGL
# (EGL + Mesa), open3d (libusb-1.0) and the results site's browser test (chromium and
# chromium-driver), then a virtual environment in .venv with the package and its test, notebook
# and docs tools. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")"

packages="libegl1 libegl-mesa0 libgl1-mesa-dri libgomp1 libusb-1.0-0 chromium chromium-driver"
missing=$(dpkg-query -W -f='${Package} ${Status}\n' $packages 2>/dev/null | grep -vc "install ok installed" || true)
if ! dpkg-query -W $packages >/dev/null 2>&1 || [ "$missing" != "0" ]; then
    sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq $packages >/dev/null
fi

python=${PYTHON:-python3}
[ -x .venv/bin/python ] || "$python" -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[test,notebook,docs]'
# compile the numba kernels once, now, into their disk cache (every experiment's tiny run, two at
# a time), so that the first run compiles little; WORKBENCH_NO_WARM=1 skips it
[ -n "${WORKBENCH_NO_WARM:-}" ] || .venv/bin/workbench warm --jobs 2
echo "workbench installed in .venv ($(.venv/bin/workbench --version))"
